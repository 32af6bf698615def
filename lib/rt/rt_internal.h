/*
 * rt_internal.h: the runtime's private structures (lib/rt only).
 */
#ifndef MLOD_RT_INTERNAL_H
#define MLOD_RT_INTERNAL_H

#include "mlod_rt.h"

/* A loaded skeleton level's tables (level >= 1), built at load. */
typedef struct rt_skel_plan {
	uint32_t posed_count;     /* kept joints and their removed ancestors, increasing */
	uint32_t *posed;
	uint8_t *needed;          /* joint_count flags: 1 when posed */
	uint32_t kept_count;
	const uint32_t *kept;
	int32_t *stand;           /* joint_count: nearest kept ancestor-or-self */
	float *rel;               /* 16 per joint: rest transform stand-in -> joint (identity when kept) */
	const uint32_t *palette_joint;
	const float *palette_bind;
	uint32_t *palette_src;    /* palette_size: the first entry with the same joint and bind (rt_palette_sources) */
} rt_skel_plan;

enum { RT_UNIT_ABSENT = 0, RT_UNIT_RESIDENT = 1, RT_UNIT_FAILED = 2 };

/* One level of one layer (and clip for motion): the cache's unit. */
typedef struct rt_unit {
	uint8_t layer;            /* mlod_rt_layer */
	uint8_t state;            /* RT_UNIT_* */
	uint8_t coarse;           /* pinned: the coarsest level */
	uint8_t owned;            /* decoded by the runtime (pack source) */
	uint8_t retry;            /* failed by a transient cause (NOMEM, IO): the next
	                           * mlod_rt_stream tries it again */
	uint8_t no_room;          /* the last mlod_rt_stream found no room for it in the
	                           * budget (defer_want): mlod_rt_level_info.no_room */
	uint16_t level, item;
	int32_t chunk;            /* TOC index, -1 for views */
	uint32_t stored_size, raw_size;
	float error, distance;
	size_t bytes;             /* counted while resident */
	size_t need;              /* a pack's level: its resident bytes, from its part, channel
	                           * or kept-joint records (rt_mesh_reserve,
	                           * rt_motion_reserve, rt_skel_reserve); 0 until a
	                           * load read them */
	uint64_t last_wanted;     /* the update stamp */
	uint32_t want_count;      /* instances wanting it at the last update */
	uint32_t users;           /* instances showing it */
	uint32_t vertex_count;    /* mesh levels: vertices over all parts */
	/* Resident data. */
	const void *view;         /* views: the caller's struct */
	union {
		mlod_pack_skel_level skel;
		mlod_pack_mesh mesh;
		mlod_pack_motion motion;
	} dec;                    /* pack source: decoded here */
	const mlod_pack_skel_level *skel;
	const mlod_pack_mesh *mesh;
	const mlod_pack_motion *motion;
	rt_skel_plan plan;        /* skeleton levels >= 1 */
	/* Mesh levels (rt_prepare_mesh): the palette entries its skinned vertices
	 * read (every influence the kernel blends, up to the last non-zero
	 * weight), increasing, and the joints its rigid parts follow. */
	uint32_t pal_used_count, rigid_count;
	uint32_t *pal_used, *rigid;
	/* Mesh levels: per part, the offset in skin_order of its buckets
	 * (rt_skin_order; skinned parts), all in plan_block; for a rigid or
	 * static part 1 when its normals all have unit length to within
	 * RT_UNIT_TOL (mlod_rt_skin may then skip renormalising them), else 0. */
	uint32_t *skin_order_at;
	uint8_t *skin_order;
	/* Mesh levels (rt_prepare_mesh), for mlod_rt_bounds, in plan_block.
	 * Per palette entry 13 floats: over the level's skinned vertices
	 * weighted to it (weight > 0), the box of their bind-pose positions
	 * (centre x, y, z, half extents x, y, z), the radius of the ball
	 * about that centre that holds them (-1 when no vertex is weighted to
	 * the entry), and the box of those positions in the entry's joint
	 * space, by its inverse bind (centre, half extents; half extent x -1
	 * when ctx->pal_bind_inv has none or a coordinate is not finite). Per
	 * part 7 floats: for a rigid or static part the box and ball of its
	 * positions (before its offset) as above, radius -1 for a skinned part
	 * or one without vertices. Per part i, its morph targets' longest
	 * deltas, bound_morph + bound_morph_at[i] .. bound_morph +
	 * bound_morph_at[i + 1] - 1. */
	float *bound_entry;       /* 13 per palette entry */
	float *bound_part;        /* 7 per part */
	float *bound_morph;
	uint32_t *bound_morph_at; /* part_count + 1 */
	uint8_t *chan_flags;      /* resident motion levels: a bit per channel (in ctx->chan_bits) */
	/* Resident motion levels, in plan_block. Per joint (fixed): 0 when a
	 * channel of it has more than one key (animated: sampled per frame);
	 * else its local matrix is fixed, made at load: 1, no channel:
	 * ctx->rest_mat; k >= 2, its channels all have one key: static_mat +
	 * 16 * (k - 2), rt_trs_cols of the rest transform after those keys.
	 * anim: the channels of the animated joints, in the level's order (so
	 * a later channel of the same joint and path still wins). */
	uint32_t *fixed;          /* joint_count */
	uint32_t *anim;           /* anim_count */
	uint32_t anim_count;
	float *static_mat;        /* 16 per joint with one-key channels only */
	void *plan_block;
} rt_unit;

struct mlod_rt_ctx;
/* The source: decodes a unit into u->dec (pack source, rt_pack.c), frees
 * it, and closes the source. NULL for views. */
typedef mlod_result (*rt_load_fn)(struct mlod_rt_ctx *ctx, rt_unit *u, mlod_error *err);
typedef void (*rt_unload_fn)(struct mlod_rt_ctx *ctx, rt_unit *u);
typedef void (*rt_close_fn)(struct mlod_rt_ctx *ctx);

typedef struct rt_instance {
	mlod_rt_state st;
	uint32_t next_free;
	uint32_t gen;             /* the slot's generation: one more per destroy (rt_slot_id) */
	int selected;             /* 0 until the first update: no hysteresis then */
} rt_instance;

struct mlod_rt_ctx {
	mlod_rt_allocator alloc;
	size_t budget;
	uint64_t open_tag;        /* this open's, one per context in the process, never 0:
	                           * mlod_rt_skin_stale's records name it (rt_ctx_new) */
	rt_load_fn load;
	rt_unload_fn unload;
	rt_close_fn close_source;
	/* Source. */
	int source;               /* 0 views, 1 memory, 2 read callback (path uses 2) */
	const uint8_t *data;
	size_t size;
	mlod_rt_read_fn read;
	void *read_user;
	void *file;               /* FILE * for open_path */
	uint64_t file_size;
	mlod_pack pack;
	int pack_open;
	mlod_pack_chunk *shadow;  /* a copy of the TOC for decoding from the staging buffer */
	uint8_t *staging;
	size_t staging_size;
	mlod_pack_info info;
	mlod_pack_skeleton skel_dec;
	int skel_owned, info_owned;
	/* The character. */
	const mlod_pack_skeleton *skel;
	uint32_t joint_count, skin_count, palette_size;
	uint32_t *skin_offset;    /* skin_count: first palette entry of each skin */
	float *rest_world;        /* 16 per joint */
	float *rest_mat;          /* 16 per joint: the local matrix of the rest transform */
	mlod_trs *rest_local;     /* joint_count */
	uint32_t *all_joints;     /* 0..joint_count-1: level 0's posed and kept list */
	uint8_t *all_needed;      /* joint_count ones */
	uint32_t *pal_joint0;     /* palette_size: the joint each entry follows at level 0 */
	const float **pal_bind0;  /* palette_size: its inverse bind matrix */
	float *pal_bind_inv;      /* 16 per palette entry: the inverse of its inverse bind (the
	                           * joint's bind-pose world matrix), or all 0 when that is
	                           * singular or not finite (mlod_rt_bounds) */
	uint32_t *pal_src0;       /* palette_size: the first entry with the same joint and bind */
	uint32_t levels[MLOD_RT_LAYERS];
	uint32_t clip_count;
	float *clip_duration;
	/* Per motion unit, a bit per channel (the first 3 x joint_count): set
	 * when the channel is a non-cubic rotation whose keys are each their
	 * own mlod_quat_normalize, so sampling need not normalise them.
	 * Allocated at open, chan_bytes per motion unit. */
	uint8_t *chan_bits;
	uint32_t chan_bytes;
	/* Units: skeleton levels, mesh levels, then motion clip-major. */
	rt_unit *units;
	uint32_t unit_count;
	uint32_t unit_base[MLOD_RT_LAYERS];
	/* Cache. */
	size_t resident_bytes, peak_bytes;
	size_t open_bytes;        /* resident_bytes when open had loaded what it pins */
	uint64_t stamp;
	int streamed;             /* mlod_rt_stream ran since the last update or request:
	                           * the next one starts a new frame's wants (rt_begin_frame) */
	uint64_t loads, evictions, failures;
	uint64_t unit_gen;        /* counts loads and releases: keys the scratch's skin plan */
	rt_unit *loading;         /* the unit ctx->load decodes (rt_mesh_reserve) */
	int streaming;            /* inside mlod_rt_stream: rt_mesh_reserve makes room */
	int refused;              /* rt_mesh_reserve found no room: the load is not a failure */
	uint32_t max_vertices;    /* mlod_rt_max_vertex_count: INFO's max_vertex_count from open on
	                           * (a pack of format 8.1 on) or the views' largest mesh level;
	                           * else (older packs) the largest mesh level resident so far */
	/* Per chunk of a read source, 1 once its bytes matched its CRC when
	 * read (rt_pack.c read_chunk): such a chunk failing its CRC later was
	 * misread, not corrupt. NULL for memory and views. */
	uint8_t *verified;
	/* Instances. */
	rt_instance *inst;
	uint32_t max_instances, free_head, live;
	/* An id is the slot's index in its low slot_bits bits and the slot's
	 * generation above them (rt_slot_id); slot_bits 32 leaves no
	 * generation (a pool of more than 2^31). */
	uint32_t slot_bits;
	/* Morph target weights (morph_setup): per part its targets' weights,
	 * morph_total per instance, the instance's at morph_weights + slot *
	 * morph_total; morph_parts 0 when no part has targets. */
	uint32_t part_count;      /* mesh parts (morph_setup): the coarsest level's, or views' most */
	uint32_t morph_parts, morph_total;
	uint32_t *morph_offset;   /* morph_parts + 1: first weight of each part */
	float *morph_weights;     /* max_instances * morph_total, or NULL */
};

struct mlod_rt_scratch {
	const mlod_rt_ctx *owner; /* the context it was made for (checked by every call) */
	mlod_trs *local;          /* joint_count */
	float *world;             /* 16 per joint */
	float *palette;           /* 16 per palette entry */
	float *lm;                /* the pose's animated local matrices, 8 at a time by entry (rt_eval.c) */
	uint32_t *anim_joints;    /* the pose's animated joints, in order (joint_count + 7) */
	const rt_unit *skel_unit; /* the pose's skeleton level (NULL: level 0) */
	int posed, paletted;      /* posed: 1 in full (mlod_rt_pose), 2 only what a mesh level needs */
	uint32_t id;              /* the instance posed */
	/* Everything a pose of a mesh level (posed 2) depends on besides id
	 * (whose generation changes with its instance) and skel_unit: the
	 * resident levels (unit_gen), the mesh level, the clip, its level and
	 * the time. mlod_rt_skin after mlod_rt_bounds of the same instance,
	 * nothing of these changed, takes the pose as it is (pose_mesh_level). */
	uint64_t pose_unit_gen;
	const rt_unit *pose_mesh;
	float pose_time;
	uint32_t pose_clip, pose_motion_level;
	/* The skin plan (mlod_rt_skin): the joints that the mesh level mesh
	 * under the skeleton level skel needs posed (need: a flag per joint;
	 * posed: their list, increasing), valid while ctx->unit_gen is gen. */
	const rt_unit *plan_skel, *plan_mesh;
	uint64_t plan_gen;
	int plan_valid;
	uint32_t plan_count;
	uint32_t *plan_posed;
	uint8_t *plan_need;
	/* The palette entries mlod_rt_skin made in this call: pal_mark[e] is
	 * pal_stamp when entry e holds this pose's matrix. */
	uint32_t *pal_mark;
	uint32_t pal_stamp;
};

/* rt_ctx.c: allocation through the context's allocator (rt_calloc: n
 * zeroed elements, NULL on overflow), an empty context, and a unit
 * (rt_unit_at below). */
void *rt_alloc(const mlod_rt_ctx *ctx, size_t size);
void rt_free(const mlod_rt_ctx *ctx, void *p);
void *rt_calloc(const mlod_rt_ctx *ctx, size_t n, size_t size);
mlod_rt_ctx *rt_ctx_new(const mlod_rt_config *config);
/* Lays out ctx's levels and units (a pack's and views' opens alike): the
 * level counts per layer (no motion levels without clips, no clips
 * without motion levels), unit_count, unit_base, and the units zeroed;
 * -1 when they cannot be allocated. The counts are checked (at most
 * 65,535 each) by the caller. */
int rt_units_make(mlod_rt_ctx *ctx, uint32_t skel_levels, uint32_t mesh_levels, uint32_t clip_count,
                  uint32_t motion_levels);
rt_unit *rt_unit_get(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item);
/* 1 when config's allocator has one of malloc and free (both or neither). */
int rt_config_bad(const mlod_rt_config *config);

/* rt_prepare.c: a level just made resident (u->skel, u->mesh or
 * u->motion set), checked, with the runtime's tables of it built in
 * u->plan_block (rt_unit above); on failure the caller releases it. */
mlod_result rt_prepare_skel(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_skel_level *l, mlod_error *err);
mlod_result rt_prepare_mesh(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_mesh *m, mlod_error *err);
mlod_result rt_prepare_motion(mlod_rt_ctx *ctx, rt_unit *u, const mlod_pack_motion *m, mlod_error *err);
/* The bytes of those tables: a skeleton level's of J joints and a palette
 * of P entries; a motion level's of J joints, A channels of animated
 * joints and S joints with one-key channels only; a decoded mesh level's;
 * a mesh level's from its part records (before it decodes). */
size_t rt_skel_plan_bytes(uint32_t J, uint32_t P);
size_t rt_motion_plan_bytes(uint32_t J, uint32_t A, uint32_t S);
size_t rt_mesh_tables_bytes(const mlod_rt_ctx *ctx, const mlod_pack_mesh *m);
size_t rt_mesh_plan_bytes(const mlod_rt_ctx *ctx, const mlod_pack_part_rec *recs, uint32_t n);
/* src[e] for the n palette entries: the smallest index whose entry follows
 * the same joint with a bind matrix of the same 16 floats (bit for bit),
 * e itself for the first of them, so that a palette can copy the product
 * W[joint] * bind instead of making it again. bind[e] is entry e's matrix. */
mlod_result rt_palette_sources(const mlod_rt_ctx *ctx, uint32_t n, const uint32_t *joint,
                               const float *const *bind, uint32_t *src, mlod_error *err);

/* rt_load.c: the resident-level cache. rt_unit_load loads u (not
 * resident): on success it is resident and counted; rt_unit_release
 * gives a resident unit's data back (others are left as they are). */
mlod_result rt_unit_load(mlod_rt_ctx *ctx, rt_unit *u, mlod_error *err);
void rt_unit_release(mlod_rt_ctx *ctx, rt_unit *u);
/* The level loaded for an instance wanting level w: w, or the finest
 * coarser level not failed. */
uint32_t rt_want_target(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t item, uint32_t w);
/* A frame's wants (mlod_rt_stream(3)) are those of every update and
 * request since the last mlod_rt_stream: the first of them after a stream
 * (or open) clears the last frame's, later ones add to them. */
void rt_begin_frame(mlod_rt_ctx *ctx);
/* n more wants of u in this frame (saturating below the high bit, which
 * mlod_rt_stream uses), stamped now for the eviction order. */
void rt_want(mlod_rt_ctx *ctx, rt_unit *u, uint32_t n);
/* The pack reader's reserve callback (pack_internal.h) for a mesh level's
 * load, user the context: sets ctx->loading's need from the level's part
 * records and, inside mlod_rt_stream, makes room for it (evicting as
 * mlod_rt_stream does) or refuses with MLOD_ERR_LIMIT and ctx->refused
 * set. */
mlod_result rt_mesh_reserve(void *user, const mlod_pack_part_rec *parts, uint32_t part_count, mlod_error *err);
/* The same for a motion level's load (its channel records and its block's
 * size, mlod_pack_motion_reserve_fn). */
mlod_result rt_motion_reserve(void *user, const mlod_pack_channel_rec *channels, uint32_t channel_count,
                              uint64_t block_bytes, mlod_error *err);
/* The same for a skeleton level's load (its kept joints and palette
 * entries, checked; mlod_pack_skel_reserve_fn). */
mlod_result rt_skel_reserve(void *user, uint32_t kept_count, uint32_t palette_size, uint64_t block_bytes,
                            mlod_error *err);
/* Byte counts of decoded views (from their arrays). */
size_t rt_bytes_skel_level(const mlod_pack_skel_level *l);
size_t rt_bytes_mesh(const mlod_pack_mesh *m);
size_t rt_bytes_motion(const mlod_pack_motion *m);

/* rt_instance.c: an instance's shown levels resolved from its wanted ones
 * and the resident levels (the fallback rule), with the users counts. */
void rt_resolve(mlod_rt_ctx *ctx, rt_instance *in);

/* rt_open.c: the common part of every open, once the source has set the
 * skeleton, the levels and the units: on failure the caller closes. */
mlod_result rt_ctx_finish_open(mlod_rt_ctx *ctx, mlod_error *err);

/* rt_skin.c: the vertices of a rigid or static part (or a stretch of
 * them) by the affine M: the point M p and the normal M n normalised (nrm
 * NULL: zero normals; out_nrm NULL: none), each coordinate summed in the
 * order M[r] x + M[4 + r] y + M[8 + r] z (+ M[12 + r]), the normal's
 * squared length as x x + y y + z z, then times 1 / sqrt of it (0 when
 * not positive): the same floats whichever path computes them. With U
 * not NULL the normal is U n (U's first three columns, the same order of
 * sums), not normalised: for M's linear part a rotation times a scale s
 * and unit input normals, mlod_rt_skin passes U = M / s (rigid_unit). */
void rt_transform(size_t n, const float *pos, const float *nrm, const float *M, const float *U, float *out_pos,
                  size_t ps, float *out_nrm, size_t ns);

/* rt_skin.c: the influence-count buckets of a skinned part (rt_prepare_mesh
 * builds them when a mesh level loads, so mlod_rt_skin_lbs's per-run
 * bucketing is not redone every frame). For n vertices in runs of
 * RT_SKIN_RUN, order holds RT_SKIN_ORDER_BYTES(n) bytes: first n, per run
 * the offsets within the run of its vertices with one influence of
 * weight exactly 1, then 1, 2, 3 and 4 influences (up to the last
 * non-zero weight, at least 1; increasing in each bucket), then 5 per
 * run, the run's five bucket sizes.
 * rt_skin_lbs_ordered is mlod_rt_skin_lbs given them (list: order + v0,
 * counts: order + n + 5 v0 / RT_SKIN_RUN of the same part, for v0 a
 * multiple of RT_SKIN_RUN): the same floats. */
#define RT_SKIN_RUN 64
/* The relative tolerance of a unit normal's length and of a rigid
 * matrix's linear part as a rotation times a scale (rigid_unit). */
#define RT_UNIT_TOL 1e-6
#define RT_SKIN_ORDER_BYTES(n) ((size_t)(n) + 5 * (((size_t)(n) + RT_SKIN_RUN - 1) / RT_SKIN_RUN))
void rt_skin_order(size_t n, const float *weights, uint8_t *order);
void rt_skin_lbs_ordered(size_t n, const float *positions, const float *normals, const uint16_t *joints,
                         const float *weights, const float *palette, float *out_pos, size_t pos_stride,
                         float *out_nrm, size_t nrm_stride, const uint8_t *list, const uint8_t *counts);

/* rt_math.h: the affine helpers rt_mat_mul (a * b), rt_mat_trs
 * (mlod_mat4_from_trs) and rt_mat_mul_trs (parent * rt_mat_trs(t)). */
#include "rt_math.h"

/* Level level of a layer (and clip item of the motion layer), or NULL out
 * of range: rt_unit_get (rt_ctx.c), and the same inline, rt_unit_at, for
 * rt_instance.c and rt_load.c, whose loops look levels up for every
 * instance at every update (resolve_layer, rt_want_target): they were one
 * file with rt_unit_get, which the compiler inlined there. The other
 * files call rt_unit_get, as they did: inlined into rt_eval.c, it made
 * mlod_rt_pose 0.4% costlier under callgrind (bench_bounds, Run 101). */
static inline rt_unit *rt_unit_at(const mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item)
{
	if ((unsigned)layer >= MLOD_RT_LAYERS || level >= ctx->levels[layer])
		return NULL;
	if (layer == MLOD_RT_MOTION) {
		if (item >= ctx->clip_count)
			return NULL;
		return &ctx->units[ctx->unit_base[layer] + item * ctx->levels[layer] + level];
	}
	return &ctx->units[ctx->unit_base[layer] + level];
}

/* The id of slot i as it is now: its index and its generation. */
static inline uint32_t rt_slot_id(const mlod_rt_ctx *ctx, uint32_t i)
{
	return ctx->slot_bits >= 32 ? i : ctx->inst[i].gen << ctx->slot_bits | i;
}

/* The slot an id names (its index in inst), whether alive or not. */
static inline uint32_t rt_slot(const mlod_rt_ctx *ctx, uint32_t id)
{
	return ctx->slot_bits >= 32 ? id : id & ((1u << ctx->slot_bits) - 1u);
}

/* The live instance id names, or NULL: a slot out of range, not alive, or
 * alive with another generation (id outlived its instance). */
static inline rt_instance *rt_live(const mlod_rt_ctx *ctx, uint32_t id)
{
	const uint32_t i = rt_slot(ctx, id);
	if (i >= ctx->max_instances || !ctx->inst[i].st.alive || rt_slot_id(ctx, i) != id)
		return NULL;
	return &ctx->inst[i];
}

#endif
