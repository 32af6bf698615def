/*
 * packwrite_internal.h: internal to lib/pack's writer (mlod_pack_write.h
 * is the public API). What its files share: the aligned append and the
 * little-endian writers on the byte buffer (mlod_buf), the chunks, the character as packed (struct ctx), the MOTION chunk as the
 * reader returns it, and the functions one file calls in another
 * (prefixed pack_; every other function stays static in its file). A
 * function's comment stays at its definition.
 *
 * The files, each a layer of the writer, each calling only files below it
 * (scripts/check-call-cycles):
 *
 *   packwrite.c    mlod_pack_write: the layers' levels, then their chunks
 *                  coarsest first, the INFO and DOC chunks, the TOC
 *   motionhold.c   motion levels held to their bounds as read back, the
 *                  lattice shifts kept where they pay, a chunk's error as
 *                  read back
 *   packmotion.c   motion levels and MOTION chunks (the rotation lattice)
 *   packskel.c     skeleton levels and SKELETON chunks
 *   packdoc.c      the document the DOC chunk keeps
 *   packbound.c    mesh levels: the input's bound to skeleton levels, or
 *                  computed
 *   packmesh.c     MESH chunks (layout b2, or Draco meshes)
 *   packchar.c     the character as packed: the view of the input, its
 *                  rest measures, notes and warnings, the attributes the
 *                  pack does not store
 *   packbuf.c      bytes, a chunk's streams and container, the entropy
 *                  stage
 *
 * The small writers are static inline here (as mlod_buf's appends are in
 * mlod_core.h), so that they stay inlined where they were (the build is
 * -O2 without LTO).
 */
#ifndef MLOD_PACKWRITE_INTERNAL_H
#define MLOD_PACKWRITE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pack/mlod_pack_write.h"
#include "record/mlod_record.h"

/* ------------------------------------------------------------------ */
/* Bytes                                                               */
/* ------------------------------------------------------------------ */

/* The pack's aligned appends, on the library's byte buffer (mlod_buf,
 * mlod_core.h): zeros up to the next multiple of align. */
static inline void buf_pad(mlod_buf *b, size_t align)
{
	if (b->size % align)
		mlod_buf_append_zeros(b, align - b->size % align);
}

static inline void put_u16(uint8_t *p, uint16_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
}

static inline void put_u32(uint8_t *p, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static inline void put_u64(uint8_t *p, uint64_t v)
{
	for (int i = 0; i < 8; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static inline void put_f32(uint8_t *p, float f)
{
	uint32_t u;
	memcpy(&u, &f, 4);
	put_u32(p, u);
}

/* ------------------------------------------------------------------ */
/* Chunks and their streams (packbuf.c)                                */
/* ------------------------------------------------------------------ */

typedef struct stream {
	uint32_t tag, count;
	uint16_t size;
	int index;       /* an index stream (the index codec may apply) */
	uint8_t *data;   /* count * size bytes, owned */
} stream;

typedef struct chunkb {
	stream *s;
	int n, cap;
	int fail;
} chunkb;

typedef struct chunk {
	uint32_t type;
	uint8_t layer, codec, entropy;
	uint16_t level, item, flags;
	float error, distance;
	uint8_t *data;
	size_t size;
	uint32_t raw, coded; /* coded: with an entropy stage, the container's size */
	uint64_t offset;
} chunk;

typedef struct chunks {
	chunk *c;
	int n, cap;
} chunks;

void pack_cb_add(chunkb *cb, uint32_t tag, uint32_t count, uint16_t size, const void *data, int index);
void pack_cb_free(chunkb *cb);
size_t pack_stream_coded_bytes(const stream *s);
size_t pack_cb_coded_bytes(const chunkb *cb, int from);
mlod_result pack_cb_finish(chunkb *cb, mlod_pack_codec codec, chunks *out, uint32_t type, int layer, int level,
                           int item, float error, mlod_error *err);
mlod_result pack_chunk_entropy(chunk *c, const uint8_t *prefix, size_t prefix_size, mlod_error *err);
mlod_result pack_chunk_stream_choice(chunk *c, mlod_error *err);
uint32_t pack_str_add(mlod_buf *t, const char *s);

/* ------------------------------------------------------------------ */
/* The character as packed (packchar.c)                                */
/* ------------------------------------------------------------------ */

/* A clip's motion levels (packmotion.c, motionhold.c). */
struct clip_levels {
	const mlod_clip *level0;   /* the input clip, or its reduction (motion_level0) */
	float error0;              /* level 0's joint position error against the input clip */
	int count;                 /* levels >= 1 */
	int no_shifts;             /* its rotation keys all at shift 0 (motion_shift_choice) */
	int packed;                /* a pack's level 0 (extras.mlod.motion_level0): kept as read */
	const mlod_clip *clip[MLOD_PACK_MAX_MOTION_LEVELS];
	float error[MLOD_PACK_MAX_MOTION_LEVELS];
	float toc[MLOD_PACK_MAX_MOTION_LEVELS + 1]; /* per level, 0 first: its TOC error (the chunk loop) */
	/* The bounds the levels hold as read back (motion_hold), scene units;
	 * 0: none (the clip as read, a pack's levels, an input's without). */
	double bound0, bound[MLOD_PACK_MAX_MOTION_LEVELS];
	mlod_motion_level remade[MLOD_PACK_MAX_MOTION_LEVELS + 1]; /* 0 first: the levels made again */
	int chain_remade;          /* levels 1 to count are remade[1] to remade[count] */
	/* rotq_shifts' last answer (the shifts follow the clip and emin only) */
	int *shift, *tgrid, has_shift;
	double shift_emin;
	/* img_error's samples: the times and the clip as read posed there */
	float *at;
	mlod_mat4 *world;
	int samples;
};

/* The pack being made: the input, its view and each layer's levels. */
struct ctx {
	const mlod_gltf *doc;
	const mlod_character *in;
	mlod_format format;
	const mlod_pack_options *opt; /* codec draco: opt's copy with codec meshopt (the other chunks') */
	int draco;                    /* --codec draco: MESH chunks are Draco meshes (draco_level) */
	mlod_result draco_fail;       /* draco_level's failure (its message in err) */
	mlod_pack_stats *st;
	mlod_error *err;
	mlod_record rec;
	/* The view: the full skins and clips of in. */
	mlod_character v;
	int *view_skin;            /* input skin -> view skin, -1 for a level's */
	mlod_mat4 *world;          /* rest world matrices */
	float bmin[3], bmax[3], diag, height;
	/* skeleton levels >= 1, finest first */
	int skel_count;
	unsigned char *kept[MLOD_SKEL_MAX_LEVELS];
	int *remap[MLOD_SKEL_MAX_LEVELS];
	float skel_error[MLOD_SKEL_MAX_LEVELS];
	/* mesh levels >= 1 */
	int mesh_count;
	const mlod_mesh *level_mesh[MLOD_MESH_MAX_LEVELS]; /* per instance (computed) */
	int *level_node[MLOD_MESH_MAX_LEVELS];             /* per instance (from input), -1 none */
	float mesh_error[MLOD_MESH_MAX_LEVELS];
	mlod_mesh_levels ML;
	int has_ML;
	struct mpart *mp;          /* the parts of layout b2 (mesh_parts) */
	uint32_t degenerate[MLOD_MESH_MAX_LEVELS + 1]; /* per MESH level: triangles quantisation made degenerate */
	uint32_t repeated[MLOD_MESH_MAX_LEVELS + 1];   /* per MESH level: triangles repeating a vertex (the input's) */
	uint64_t max_vertices; /* INFO's max_vertex_count: the most vertices (sum over its part records) of a MESH level */
	int emptied[MLOD_MESH_MAX_LEVELS + 1];         /* per MESH level: parts left without a triangle */
	int mp_count, mp_ready;
	int **lmaps;               /* per level and instance: level_joint_map, or NULL */
	int lmap_count;
	/* motion */
	struct clip_levels *clips;
	mlod_motion_level *owned_levels;
	int owned_count;
	mlod_motion_level *level0_owned; /* per clip; clip.channels NULL where level 0 is the input's */
	struct motion_img *motion_imgs;  /* per clip, two: the last MOTION chunk written and the one before */
	int motion_count;          /* levels >= 1, over all clips */
};

void pack_note(struct ctx *x, const char *text);
/* The first len bytes of text as a note. */
void pack_note_n(struct ctx *x, const char *text, size_t len);
void pack_warn(struct ctx *x, const char *text);
int pack_joint_of_node(const mlod_skeleton *s, int node);
int pack_skin_of_gltf(const mlod_skeleton *s, int g);
int pack_mesh_of_gltf(const mlod_character *c, int g);
mlod_result pack_level_nodes(struct ctx *x, int node, int *nodes, int *max_level, double *errors,
                             double *pack_errors, int *no_error);
mlod_result pack_make_view(struct ctx *x);
mlod_result pack_measure(struct ctx *x);
mlod_result pack_note_unstored_attributes(struct ctx *x, const mlod_gltf *doc);
void pack_note_unweighted(struct ctx *x);

/* ------------------------------------------------------------------ */
/* The layers                                                          */
/* ------------------------------------------------------------------ */

/* packskel.c */
mlod_result pack_skeleton_levels(struct ctx *x);
mlod_result pack_skeleton_chunk(struct ctx *x, chunks *out);
mlod_result pack_skel_level_chunk(struct ctx *x, int k, chunks *out);

/* packbound.c */
mlod_result pack_mesh_levels(struct ctx *x);

/* packmesh.c */
void pack_mesh_parts_free(struct ctx *x);
int *pack_level_joint_map(const mlod_skeleton *s, const mlod_skin *lsk, const mlod_skin *fsk);
mlod_result pack_mesh_chunk(struct ctx *x, int k, chunks *out, int *part_count);

/* packmotion.c */

/* A MOTION chunk as the reader returns it, for the next finer level to
 * build on: per channel its key times and, for non-cubic rotations, its
 * keys as lattice integers (mlod_pack_rotq_key). */
typedef struct motion_img {
	int n;
	struct img_chan {
		uint32_t joint, path, interp, keys;
		float *times;
		int16_t *rot;
		float *vec; /* non-cubic translations and scales: the values */
	} *ch;
} motion_img;

double pack_motion_point_distance(const struct ctx *x);
mlod_result pack_motion_levels(struct ctx *x);
void pack_motion_img_free(motion_img *m);
mlod_result pack_motion_chunk(struct ctx *x, const mlod_clip *clip, int k, int item, float error,
                              const motion_img *base, motion_img *img, chunks *out);

/* motionhold.c */
mlod_result pack_motion_shift_choice(struct ctx *x, int A);
double pack_img_error(struct ctx *x, int q, const mlod_clip *clip, const motion_img *img, mlod_error *err);

/* packdoc.c */
mlod_result pack_doc_copy(const struct ctx *x, const mlod_gltf *doc, mlod_gltf **copy, mlod_error *err);
mlod_result pack_doc_dedupe(struct ctx *x, mlod_gltf *copy, int whole, mlod_error *err);
mlod_result pack_doc_strip_flags(struct ctx *x, const mlod_gltf *doc, unsigned char **flags, mlod_error *err);

#endif
