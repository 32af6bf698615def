/*
 * mlod_core.h: the common core of mlod, shared by the bake library and the
 * runtime (lib/rt): result codes and their messages, UTF-8 checks, and the
 * small math (vectors, quaternions, 4x4 matrices, TRS, Euler angles) both
 * sides use, and the one growable byte buffer (mlod_buf) the writers of
 * text and bytes build their output in.
 * It depends on nothing but the C library and POSIX threads (for
 * mlod_parallel_for), and nothing in it allocates but mlod_buf and
 * mlod_free's counterpart.
 *
 * Conventions (every part of mlod follows them)
 * - Every fallible call returns an mlod_result and, when err is not NULL,
 *   fills *err with the code and a human-readable message. The library
 *   never prints and never exits.
 * - Lengths are in the scene's units (metres for glTF, file units for BVH).
 *   Angles are radians. Matrices are column-major 4x4 (as in glTF):
 *   m[col * 4 + row].
 */
#ifndef MLOD_CORE_H
#define MLOD_CORE_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MLOD_VERSION "0.1.0"

/* ------------------------------------------------------------------ */
/* Results                                                             */
/* ------------------------------------------------------------------ */

typedef enum mlod_result {
	MLOD_OK = 0,
	MLOD_ERR_INVALID_ARG,  /* a caller error: NULL where not allowed, bad option value */
	MLOD_ERR_IO,           /* reading or writing a file failed */
	MLOD_ERR_PARSE,        /* malformed input: truncated, bad syntax, out-of-range index */
	MLOD_ERR_UNSUPPORTED,  /* well-formed input using a feature mlod does not handle */
	MLOD_ERR_NOMEM,        /* an allocation failed, or input claims an absurd size */
	MLOD_ERR_LIMIT         /* a request the data cannot satisfy (e.g. an error bound) */
} mlod_result;

#define MLOD_ERROR_MESSAGE_SIZE 512

typedef struct mlod_error {
	mlod_result code;
	char message[MLOD_ERROR_MESSAGE_SIZE]; /* says what went wrong, without a trailing newline */
} mlod_error;

/* A short static description of a result code ("malformed input", ...). */
const char *mlod_strerror(mlod_result code);

/* Fills err (if not NULL) with code and a printf-style message; returns code.
 * Used by the library itself and available to tools. */
mlod_result mlod_fail(mlod_error *err, mlod_result code, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 3, 4)))
#endif
	;

/* Releases a buffer returned by the library (glb bytes, JSON text, ...). */
void mlod_free(void *p);

/* ------------------------------------------------------------------ */
/* Byte buffer                                                         */
/* ------------------------------------------------------------------ */

/* A growable byte buffer, for output built piece by piece (BVH text, JSON,
 * a report, a pack's chunks). Zeroed (MLOD_BUF_INIT or mlod_buf_init) it
 * is empty and holds no memory. A failed growth (out of memory, or a size
 * past SIZE_MAX) sets status, frees nothing and makes every later append
 * do nothing, so a writer appends a run and checks once, at the end
 * (mlod_buf_take). While data is not NULL, data[size] is a NUL, so text
 * appended is a C string as it stands. The appends return status. */
typedef struct mlod_buf {
	unsigned char *data; /* the bytes (malloc'd), NULL until the first growth */
	size_t size;         /* bytes appended */
	size_t cap;          /* bytes allocated: at least size + 1 once data is not NULL */
	mlod_result status;  /* MLOD_OK, or why an append failed (MLOD_ERR_NOMEM) */
} mlod_buf;

#define MLOD_BUF_INIT { NULL, 0, 0, MLOD_OK }

void mlod_buf_init(mlod_buf *b);
/* Makes room for extra more bytes (and the NUL after them), growing the
 * allocation at least twofold; MLOD_ERR_NOMEM when size + extra overflows
 * or the allocation fails. */
mlod_result mlod_buf_grow(mlod_buf *b, size_t extra);

/* mlod_buf_grow when the room is not there already (inline, for the
 * appends of a few bytes that writers make per number or character). */
static inline mlod_result mlod_buf_reserve(mlod_buf *b, size_t extra)
{
	if (b->status == MLOD_OK && extra < b->cap - b->size)
		return MLOD_OK;
	return mlod_buf_grow(b, extra);
}

/* Appends n bytes of d (d may be NULL when n is 0). */
static inline mlod_result mlod_buf_append(mlod_buf *b, const void *d, size_t n)
{
	if (mlod_buf_reserve(b, n) != MLOD_OK)
		return b->status;
	if (n)
		memcpy(b->data + b->size, d, n);
	b->size += n;
	b->data[b->size] = 0;
	return MLOD_OK;
}

/* Appends the string s without its NUL. */
static inline mlod_result mlod_buf_append_str(mlod_buf *b, const char *s)
{
	return mlod_buf_append(b, s, strlen(s));
}

static inline mlod_result mlod_buf_append_char(mlod_buf *b, char c)
{
	return mlod_buf_append(b, &c, 1);
}

/* Appends n zero bytes. */
mlod_result mlod_buf_append_zeros(mlod_buf *b, size_t n);

/* Appends printf-style text (vsnprintf's, so the C locale's numbers in the
 * tools); an encoding error sets status to MLOD_ERR_INVALID_ARG. */
mlod_result mlod_buf_printf(mlod_buf *b, const char *fmt, ...)
#if defined(__GNUC__)
	__attribute__((format(printf, 2, 3)))
#endif
	;
mlod_result mlod_buf_vprintf(mlod_buf *b, const char *fmt, va_list ap);

/* Hands the bytes over: *data (for mlod_free; an empty buffer gives a
 * malloc'd ""), and *size when size is not NULL, and leaves b empty. When
 * an append failed, frees the bytes, sets *data to NULL and fails with
 * status and "out of memory writing <what>" ("out of memory" when what is
 * NULL). */
mlod_result mlod_buf_take(mlod_buf *b, char **data, size_t *size, const char *what, mlod_error *err);

/* Frees the bytes and leaves b empty (status MLOD_OK). */
void mlod_buf_free(mlod_buf *b);

/* ------------------------------------------------------------------ */
/* Text                                                                */
/* ------------------------------------------------------------------ */

/* The length (1 to 4) of the well-formed UTF-8 sequence at s, 0 for a
 * byte that does not start one (overlong forms, surrogates and code
 * points past U+10FFFF are not well formed: RFC 3629), and 1 for the NUL
 * that ends s (a sequence the NUL cuts short is not well formed). The
 * writers of JSON text put U+FFFD for such a byte. */
int mlod_utf8_length(const char *s);

/* A name from a file or a caller (NULL: "") as text that cannot break a
 * line or move the cursor, into buf (size bytes, at least 16). With quote,
 * for a one-line message: in double quotes, a quote, a backslash and a
 * control character or DEL escaped as JSON escapes them (\" \\ \n \t \r
 * \u00XX), as the tools' JSON strings (lib/io's messages quote names the
 * same way, with \u00XX for every control character). Without, for a
 * table column: C escapes (\\, \n, \t, \r, \xHH for any other control
 * character and DEL), as the tools' tables write names. Either way a byte that is not UTF-8 is
 * \xHH. A name too long for buf is cut between characters and ends in
 * "...". Returns buf. */
#define MLOD_NAME_TEXT_SIZE 160

/* Text of lines (the reader's notes and warnings: one a line), line by
 * line: the line at *at (up to its '\n' or the end, without the '\n') as
 * its start and *len; *at moves past it. NULL once *at is NULL or at the
 * end. for (const char *w = text, *l; (l = mlod_next_line(&w, &n));) */
const char *mlod_next_line(const char **at, size_t *len);
const char *mlod_name_text(const char *name, int quote, char *buf, size_t size);
/* mlod_name_text(name, 1, ...) in a buffer that lives to the end of the
 * enclosing block (C only: a compound literal), for a message:
 * mlod_fail(err, code, "clip %s: ...", MLOD_QUOTED(clip->name)). */
#define MLOD_QUOTED(name) mlod_name_text((name), 1, (char[MLOD_NAME_TEXT_SIZE]){0}, MLOD_NAME_TEXT_SIZE)

/* The one escaper of a name from the input or the pack (the character's,
 * a clip's, a joint's, the input's, a note naming a joint or mesh) written
 * to f whole, for the tools' output and mlod_pack_print_info's: with json,
 * as a JSON string (in double quotes; quote, backslash and control
 * characters escaped, a byte that is not UTF-8 as \ufffd); else for a
 * table with C escapes (\n, \t, \r, \\, \xHH for any other control
 * character, DEL and a byte that is not UTF-8), padded to width columns
 * (0: none) counting each UTF-8 character as one, so that a name never
 * breaks a line or a column. With f NULL it writes nothing. Returns the
 * table form's columns (unpadded). */
int mlod_name_put(FILE *f, const char *name, int json, int width);
/* Appends "v0, v1, ..." (the first `most` of the n values, then ", ..."
 * when there are more) to the string in buf, within size bytes. */
void mlod_int_list(char *buf, size_t size, const int *v, int n, int most);

/* ------------------------------------------------------------------ */
/* Threads                                                             */
/* ------------------------------------------------------------------ */

#define MLOD_MAX_THREADS 64

/* The number of processors this process may run on (its CPU affinity
 * where the system tells it, else those online; 1 when unknown), at most
 * MLOD_MAX_THREADS: the tools' default for -j. */
int mlod_thread_count(void);

/* One work item: fills only item i's own results. */
typedef mlod_result (*mlod_parallel_fn)(void *ctx, int i);

/* Runs fn(ctx, i) for i in [0, n) on up to `threads` threads (the caller's
 * among them; 0 or 1: a plain loop on the caller's thread). Returns the
 * result of the first failing item in index order (items after it may not
 * run), else MLOD_OK. Results do not depend on the thread count. */
mlod_result mlod_parallel_for(int n, int threads, mlod_parallel_fn fn, void *ctx);

/* ------------------------------------------------------------------ */
/* Math                                                                */
/* ------------------------------------------------------------------ */

#define MLOD_PI 3.14159265358979323846

/* The largest |length - 1| of a rotation quaternion taken as unit: the
 * Khronos glTF validator's (ROTATION_NON_UNIT past it). The glTF reader
 * normalises a node rotation past it, with a note; the pack reader
 * refuses a joint's rest rotation past it. */
#define MLOD_UNIT_QUAT_TOLERANCE 0.00769

/* The length of (x, y, z, w) in double, without overflow: NaN when a
 * component is not finite. */
double mlod_quat4_length(double x, double y, double z, double w);

/* a wrapped into (-pi, pi]: an angle difference taken the short way. */
double mlod_wrap_angle(double a);

typedef struct mlod_v3 { float x, y, z; } mlod_v3;
typedef struct mlod_quat { float x, y, z, w; } mlod_quat;  /* glTF order */
typedef struct mlod_mat4 { float m[16]; } mlod_mat4;         /* column-major */

/* A local transform: translation, rotation, scale (glTF's TRS). */
typedef struct mlod_trs {
	mlod_v3 t;
	mlod_quat r;
	mlod_v3 s;
} mlod_trs;

/* Euler orders. MLOD_EULER_ZXY means the rotation matrix is Rz * Rx * Ry:
 * the order in which BVH lists "Zrotation Xrotation Yrotation". */
typedef enum mlod_euler_order {
	MLOD_EULER_XYZ,
	MLOD_EULER_XZY,
	MLOD_EULER_YXZ,
	MLOD_EULER_YZX,
	MLOD_EULER_ZXY,
	MLOD_EULER_ZYX
} mlod_euler_order;

mlod_v3 mlod_v3_add(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_sub(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_scale(mlod_v3 a, float s);
float mlod_v3_dot(mlod_v3 a, mlod_v3 b);
mlod_v3 mlod_v3_cross(mlod_v3 a, mlod_v3 b);
float mlod_v3_length(mlod_v3 a);

mlod_quat mlod_quat_identity(void);
mlod_quat mlod_quat_mul(mlod_quat a, mlod_quat b);         /* a then applied after b: a*b */
mlod_quat mlod_quat_normalize(mlod_quat q);
mlod_quat mlod_quat_conjugate(mlod_quat q);
mlod_v3 mlod_quat_rotate(mlod_quat q, mlod_v3 v);
mlod_quat mlod_quat_axis_angle(mlod_v3 axis, float angle); /* axis need not be unit */
mlod_quat mlod_quat_slerp(mlod_quat a, mlod_quat b, float t); /* shortest path */
mlod_quat mlod_quat_nlerp(mlod_quat a, mlod_quat b, float t); /* shortest path */
/* Angle in [0, pi] between the rotations a and b; q and -q are the same rotation. */
float mlod_quat_angle(mlod_quat a, mlod_quat b);

/* angles[0..2] are the rotations about x, y, z (radians), whatever the order. */
mlod_quat mlod_quat_from_euler(mlod_euler_order order, const float angles[3]);
void mlod_quat_to_euler(mlod_euler_order order, mlod_quat q, float angles[3]);
/* Parses "XYZ", "zxy", ... ; returns 0 on success, -1 when not an order. */
int mlod_euler_order_parse(const char *s, mlod_euler_order *out);
const char *mlod_euler_order_name(mlod_euler_order order);
/* The axes (0 x, 1 y, 2 z) of an order, outermost first: order ABC is
 * RA * RB * RC. An invalid order gives XYZ's. */
const int *mlod_euler_axes(mlod_euler_order order);

mlod_mat4 mlod_mat4_identity(void);
mlod_mat4 mlod_mat4_mul(const mlod_mat4 *a, const mlod_mat4 *b); /* a*b */
mlod_mat4 mlod_mat4_from_trs(const mlod_trs *trs);
/* Decomposes an affine matrix. Returns 0 when it is exactly a TRS (no shear,
 * within tol relative), 1 when it has shear the TRS cannot express (the
 * result is then the closest TRS), -1 when singular. */
int mlod_mat4_to_trs(const mlod_mat4 *m, mlod_trs *out, float tol);
/* General inverse; returns 0 on success, -1 when singular. */
int mlod_mat4_invert(const mlod_mat4 *m, mlod_mat4 *out);
mlod_v3 mlod_mat4_point(const mlod_mat4 *m, mlod_v3 p);  /* m * (p, 1) */
mlod_v3 mlod_mat4_vector(const mlod_mat4 *m, mlod_v3 v); /* m * (v, 0) */
/* An upper bound of the largest singular value of w's 3x3 part M: the
 * square root of the largest absolute row sum of M^T M (Gershgorin),
 * exact for a rotation times a uniform scale. */
double mlod_mat4_sigma_bound(const mlod_mat4 *w);
mlod_trs mlod_trs_identity(void);


#ifdef __cplusplus
}
#endif

#endif /* MLOD_CORE_H */
