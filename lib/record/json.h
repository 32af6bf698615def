/*
 * json.h: the record module's own JSON: a strict reader into a small tree
 * and a writer back to text. Internal to lib/record (the public API is
 * mlod_record.h).
 *
 * Why a C module rather than nlohmann through the shim: the record is read
 * and merged as whole objects, and lib/io sits below lib/record, so the
 * shim cannot know the record's types; the shim hands the record over as
 * JSON text (mlod_gltf_get_extra) and takes it back the same way.
 *
 * The reader follows RFC 8259 strictly (no comments, no trailing commas,
 * no leading zeros, no control characters in strings, valid \u escapes and
 * surrogate pairs, nothing after the value), nests at most MJ_MAX_DEPTH
 * deep, and refuses text over MJ_MAX_SIZE: hostile text gets a message,
 * never a crash. Numbers keep their text, so a value read and written back
 * is the same number to the last digit.
 */
#ifndef MLOD_RECORD_JSON_H
#define MLOD_RECORD_JSON_H

#include <stddef.h>

#define MJ_MAX_DEPTH 64
#define MJ_MAX_SIZE ((size_t)256 << 20)

typedef enum mj_type { MJ_NULL, MJ_FALSE, MJ_TRUE, MJ_NUMBER, MJ_STRING, MJ_ARRAY, MJ_OBJECT } mj_type;

typedef struct mj {
	mj_type type;
	char *text;        /* a string's UTF-8, or a number's text */
	double number;
	int count, cap;
	char **keys;       /* an object's member names */
	struct mj *items;  /* members or elements */
} mj;

/* Parses text (size bytes). Returns 0, or -1 with a message in why. */
int mj_parse(const char *text, size_t size, mj *out, char *why, size_t why_size);
void mj_free(mj *v);

/* An object's member, or NULL (also when o is not an object). */
const mj *mj_get(const mj *o, const char *key);

/* Builders: each returns 0, or -1 when out of memory. mj_put sets key of
 * object o to v (taking it over, replacing an earlier value). */
int mj_put(mj *o, const char *key, mj *v);
int mj_push(mj *a, mj *v);
mj mj_object(void);
mj mj_array(void);
/* A number written with printf format fmt ("%.9g", "%d" after a cast to
 * double is not allowed: use mj_int); null when not finite. */
int mj_double(mj *out, const char *fmt, double v);
int mj_int(mj *out, long v);
int mj_string(mj *out, const char *s);
mj mj_bool(int v);

/* Writes v as compact JSON; *text is malloc'd. Returns 0 or -1. */
int mj_write(const mj *v, char **text);

#endif
