/*
 * test_rt_budget.c: budgets that fit exactly (issue 12's probe, frictions
 * 6 and 7). A pack's motion level loads under a budget of what open
 * pinned plus that level's resident bytes, and not one byte less (the
 * room it asks before decoding is its size from its channel records, as
 * a mesh level's is from its part records; it was 4 x the TOC's raw size
 * of it and of every level it nests on); the same for every finer mesh
 * level and every skeleton level between 0 and the coarsest (from its
 * kept joints and palette; it was 4 x its raw size plus tables, less than
 * tubeman's and Ely's levels decode to, more than the BVH walk's), with
 * the peak resident bytes within the budget; from memory and through
 * read callbacks; Ely too when MLOD_SHARED_DATA names ../shared/data. A
 * motion level whose channel records claim more keys than its streams
 * hold (CRCs fixed) fails that level alone, within the budget (its
 * fallback loads); so does a skeleton level whose records name a joint
 * or bind matrix it lacks, or whose 'KEPT' header or TOC raw size claims
 * more than it holds, even with no room at all (its records are checked
 * before room is asked). mlod_rt_open_*_bytes give
 * the least budget that opens (that budget opens, one byte less is
 * MLOD_ERR_LIMIT), equal to mlod_rt_stats.open_bytes, for each source.
 *
 * The packs come from mlod-pack on the committed samples (rt_packer.h);
 * without it the tests print SKIP. Links libmlodrt.a alone.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rt_test.h"
#include "rt_packer.h"

static struct pk {
	const char *sample, *opts, *file;
	char path[512];
	uint8_t *data;
	size_t size;
} packs[] = { { "samples/tubeman.glb", "", "bud-tube.mlod", "", NULL, 0 },
	      { "samples/RobotExpressive.glb", "", "bud-robot.mlod", "", NULL, 0 },
	      { "samples/cmu_12_01_walk.bvh", "", "bud-bvh.mlod", "", NULL, 0 },
	      /* stream codecs and the entropy stage off: the records can be edited */
	      { "samples/tubeman.glb", "--codec none --entropy none", "bud-tube-raw.mlod", "", NULL, 0 } };
#define PACKS (sizeof packs / sizeof packs[0])
#define RAW 3

static int packs_ready(void)
{
	for (size_t p = 0; p < PACKS; p++) {
		if (packs[p].data)
			continue;
		if (run_pack(packs[p].sample, packs[p].opts, packs[p].file, packs[p].path, sizeof packs[p].path) != 0 ||
		    !(packs[p].data = read_all(packs[p].path, &packs[p].size)))
			return 0;
	}
	return 1;
}

/* Opens pack k from memory (how 0) or read callbacks (how 1). */
static mlod_result open_how(const struct pk *k, int how, rt_mem_source *src, size_t budget, mlod_rt_ctx **ctx,
                            mlod_error *e)
{
	mlod_rt_config cfg = { budget, 4, NULL };
	*src = (rt_mem_source){ k->data, k->size, 0, 0 };
	return how ? mlod_rt_open_read(rt_mem_read, src, k->size, &cfg, ctx, e)
	           : mlod_rt_open_memory(k->data, k->size, &cfg, ctx, e);
}

/* Requests a level, streams once; its info after. */
static void load_one(mlod_rt_ctx *ctx, mlod_rt_layer layer, uint32_t level, uint32_t item, mlod_rt_level_info *li)
{
	mlod_error e = { 0 };
	memset(li, 0, sizeof *li);
	CHECK_OK(mlod_rt_request(ctx, layer, level, item, &e), e);
	CHECK_OK(mlod_rt_stream(ctx, SIZE_MAX, NULL, &e), e);
	CHECK_OK(mlod_rt_level_info_get(ctx, layer, level, item, li, &e), e);
}

/* Every finer level of pack k (skeleton levels but 0 and the coarsest,
 * mesh levels, motion levels of the first three clips) from memory and
 * through read callbacks: its resident bytes loaded alone without a
 * budget, then under exactly what open pinned plus those bytes (it loads,
 * never passing the budget, not even while it decodes: the peak) and one
 * byte less (no room). *checked counts the budgets. */
static void levels_in_their_size(const struct pk *k, int *checked)
{
	for (int how = 0; how < 2; how++) {
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		rt_mem_source src;
		CHECK_OK(open_how(k, how, &src, 0, &ctx, &e), e);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		const size_t at_open = st.open_bytes;
		CHECK(at_open == st.resident_bytes, "%s: open_bytes %zu, resident %zu after open", k->file, at_open,
		      st.resident_bytes);
		const uint32_t clips = mlod_rt_clip_count(ctx), sl = mlod_rt_level_count(ctx, MLOD_RT_SKELETON),
		               ml = mlod_rt_level_count(ctx, MLOD_RT_MESH), tl = mlod_rt_level_count(ctx, MLOD_RT_MOTION);
		mlod_rt_close(ctx);
		for (int layer = MLOD_RT_SKELETON; layer <= MLOD_RT_MOTION; layer++) {
			const uint32_t L = layer == MLOD_RT_SKELETON ? sl : layer == MLOD_RT_MESH ? ml : tl,
			               items = layer == MLOD_RT_MOTION ? clips : 1;
			/* skeleton level 0 is the context's own, resident from open */
			for (uint32_t item = 0; item < items && item < 3; item++)
				for (uint32_t l = layer == MLOD_RT_SKELETON; l + 1 < L; l++) {
					/* its resident bytes, loaded alone without a budget */
					CHECK_OK(open_how(k, how, &src, 0, &ctx, &e), e);
					mlod_rt_level_info li, lb;
					load_one(ctx, (mlod_rt_layer)layer, l, item, &li);
					mlod_rt_close(ctx);
					CHECK(li.resident && li.bytes > 0, "%s: layer %d level %u item %u did not load", k->file,
					      layer, l, item);
					/* exactly that room admits it; one byte less does not */
					for (int less = 0; less < 2; less++) {
						CHECK_OK(open_how(k, how, &src, at_open + li.bytes - (size_t)less, &ctx, &e), e);
						load_one(ctx, (mlod_rt_layer)layer, l, item, &lb);
						mlod_rt_stats_get(ctx, &st);
						CHECK(lb.resident == !less && lb.no_room == less && !lb.failed,
						      "%s (%s): layer %d level %u item %u (%zu bytes) under %zu: resident %d, "
						      "no_room %d, failed %d",
						      k->file, how ? "read" : "memory", layer, l, item, li.bytes,
						      at_open + li.bytes - (size_t)less, lb.resident, lb.no_room, lb.failed);
						CHECK(lb.bytes == (less ? 0 : li.bytes) && st.resident_bytes <= st.budget_bytes &&
						              st.peak_resident_bytes <= st.budget_bytes,
						      "%s (%s): layer %d level %u: %zu bytes, %zu before; resident %zu, peak %zu, "
						      "budget %zu",
						      k->file, how ? "read" : "memory", layer, l, lb.bytes, li.bytes, st.resident_bytes,
						      st.peak_resident_bytes, st.budget_bytes);
						mlod_rt_close(ctx);
						(*checked)++;
					}
				}
		}
	}
}

TEST(level_loads_in_its_size)
{
	SKIP_IF_NO_PACK(level_loads_in_its_size);
	CHECK(packs_ready(), "mlod-pack failed");
	int checked = 0;
	for (size_t p = 0; p < PACKS && !t_failed_; p++)
		levels_in_their_size(&packs[p], &checked);
	if (t_failed_)
		return;
	printf("# %d budgets, each exactly a level's size or a byte less\n", checked);
	CHECK(checked > 0, "no finer level");
}

/* The same on ../shared/data's Ely (skeleton levels 1 and 2 between 0 and
 * the coarsest, four finer mesh levels), when MLOD_SHARED_DATA names it. */
TEST(ely_levels_load_in_their_size)
{
	SKIP_IF_NO_PACK(ely_levels_load_in_their_size);
	const char *dir = getenv("MLOD_SHARED_DATA");
	struct stat sb;
	if (!dir || !*dir || stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
		printf("SKIP ely_levels_load_in_their_size: needs ../shared/data: MLOD_SHARED_DATA %s\n",
		       dir && *dir ? "is not a directory" : "is not set (make test-extended sets it when ../shared/data exists)");
		return;
	}
	char sample[600];
	snprintf(sample, sizeof sample, "%.500s/Ely.glb", dir);
	struct pk ely = { sample, "", "bud-ely.mlod", "", NULL, 0 };
	CHECK(run_pack(ely.sample, ely.opts, ely.file, ely.path, sizeof ely.path) == 0 &&
	              (ely.data = read_all(ely.path, &ely.size)) != NULL,
	      "mlod-pack %s failed", sample);
	int checked = 0;
	levels_in_their_size(&ely, &checked);
	free(ely.data);
	if (t_failed_)
		return;
	printf("# Ely: %d budgets, each exactly a level's size or a byte less\n", checked);
	/* 2 skeleton and 4 mesh levels, 2 sources, 2 budgets each */
	CHECK(checked == 24, "%d budgets on Ely, not 24", checked);
}

/* The raw tubeman pack with its motion level 1 of clip 0's first
 * channel record claiming keys (delta added to its key count), CRCs
 * fixed; NULL when the records cannot be found. */
static uint8_t *claiming(uint32_t delta, uint32_t *was)
{
	const struct pk *k = &packs[RAW];
	mlod_error e = { 0 };
	mlod_pack p;
	if (mlod_pack_open(k->data, k->size, &p, &e) != MLOD_OK)
		return NULL;
	const int c = mlod_pack_find(&p, MLOD_CHUNK_MOTION, 1, 0);
	uint8_t *d = NULL;
	if (c >= 0 && p.chunks[c].entropy == MLOD_ENTROPY_NONE && (d = malloc(k->size))) {
		memcpy(d, k->data, k->size);
		uint8_t *b = d + p.chunks[c].offset, *crc = d + 32 + 48 * (size_t)c + 32;
		uint32_t tag, codec = b[4 + 10], kc;
		memcpy(&tag, b + 4, 4);
		/* stream 0 ('CHAN', raw) starts after the headers; key_count at 12 */
		uint32_t n;
		memcpy(&n, b, 4);
		uint8_t *rec = b + 4 + 16 * (size_t)n;
		if (tag != MLOD_STREAM_CHAN || codec != MLOD_SCODEC_RAW) {
			free(d);
			d = NULL;
		} else {
			memcpy(&kc, rec + 12, 4);
			*was = kc;
			kc += delta;
			memcpy(rec + 12, &kc, 4);
			/* the chunk's CRC, then the TOC's and the header's over it */
			uint32_t v = mlod_pack_crc32(0, b, p.chunks[c].stored_size);
			memcpy(crc, &v, 4);
			v = mlod_pack_crc32(0, d + 32, (size_t)p.chunk_count * 48);
			memcpy(d + 24, &v, 4);
			v = mlod_pack_crc32(0, d, 28);
			memcpy(d + 28, &v, 4);
		}
	}
	mlod_pack_close(&p);
	return d;
}

TEST(hostile_motion_claims_fail_the_level)
{
	SKIP_IF_NO_PACK(hostile_motion_claims_fail_the_level);
	CHECK(packs_ready(), "mlod-pack failed");
	const struct pk *k = &packs[RAW];
	/* one key more (within what the streams could hold: a stream falls
	 * short), and a count no stream holds (sized by nothing) */
	static const uint32_t deltas[] = { 1, 1u << 28 };
	for (size_t i = 0; i < sizeof deltas / sizeof deltas[0]; i++) {
		uint32_t was = 0;
		uint8_t *d = claiming(deltas[i], &was);
		CHECK(d, "no raw 'CHAN' stream in motion level 1 of clip 0");
		if (!d)
			return;
		mlod_error e = { 0 };
		mlod_rt_ctx *ctx = NULL;
		size_t need = 0;
		CHECK_OK(mlod_rt_open_memory_bytes(d, k->size, NULL, &need, &e), e);
		mlod_rt_config cfg = { need + 200000, 4, NULL };
		CHECK_OK(mlod_rt_open_memory(d, k->size, &cfg, &ctx, &e), e);
		CHECK_OK(mlod_rt_request(ctx, MLOD_RT_MOTION, 1, 0, &e), e);
		mlod_result r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
		CHECK(r == MLOD_ERR_PARSE, "key count %u -> %u: %s: %s", was, was + deltas[i], mlod_strerror(r), e.message);
		mlod_rt_level_info li;
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MOTION, 1, 0, &li, &e), e);
		mlod_rt_stats st;
		mlod_rt_stats_get(ctx, &st);
		CHECK(li.failed && !li.resident && st.resident_bytes <= cfg.budget_bytes &&
		      st.peak_resident_bytes <= cfg.budget_bytes,
		      "key count +%u: failed %d, resident %d; resident bytes %zu, peak %zu, budget %zu", deltas[i],
		      li.failed, li.resident, st.resident_bytes, st.peak_resident_bytes, cfg.budget_bytes);
		/* its wants passed to level 2, which loaded in the same call */
		CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_MOTION, 2, 0, &li, &e), e);
		CHECK(li.resident, "motion level 2 of clip 0 did not load in place of the failed level 1");
		mlod_rt_close(ctx);
		free(d);
	}
}

/* Fixes the CRCs of pack d (size n) after chunk c of p changed: the
 * chunk's, then the TOC's and the header's over it. */
static void fix_crcs(uint8_t *d, const mlod_pack *p, int c)
{
	uint8_t *e = d + 32 + 48 * (size_t)c;
	uint32_t v = mlod_pack_crc32(0, d + p->chunks[c].offset, p->chunks[c].stored_size);
	memcpy(e + 32, &v, 4);
	v = mlod_pack_crc32(0, d + 32, (size_t)p->chunk_count * 48);
	memcpy(d + 24, &v, 4);
	v = mlod_pack_crc32(0, d, 28);
	memcpy(d + 28, &v, 4);
}

/* The raw tubeman pack with its skeleton level 1 edited, CRCs fixed
 * (NULL when its streams are not the raw 'KEPT', 'PALR', 'PALX'): what 0,
 * its last kept joint the joint count (no such joint); 1, the 'KEPT'
 * stream's header claiming a kept joint more than it stores; 2, a 'PALR'
 * entry naming a bind matrix beyond the skin joints and 'PALX'; 3, the
 * TOC's raw size of the chunk 4 bytes more than its streams decode to. */
static uint8_t *skel_edited(int what)
{
	const struct pk *k = &packs[RAW];
	mlod_error e = { 0 };
	mlod_pack p;
	if (mlod_pack_open(k->data, k->size, &p, &e) != MLOD_OK)
		return NULL;
	const int c = mlod_pack_find(&p, MLOD_CHUNK_SKELETON, 1, 0);
	uint8_t *d = NULL;
	if (c >= 0 && p.chunks[c].entropy == MLOD_ENTROPY_NONE && (d = malloc(k->size))) {
		memcpy(d, k->data, k->size);
		uint8_t *b = d + p.chunks[c].offset, *h = b + 4;
		uint32_t n, tag[3], count[3], joints = 0;
		memcpy(&n, b, 4);
		for (int i = 0; i < 3 && (uint32_t)i < n; i++) {
			memcpy(&tag[i], h + 16 * i, 4);
			memcpy(&count[i], h + 16 * i + 4, 4);
		}
		mlod_pack_skeleton sk;
		if (mlod_pack_decode_skeleton(&p, k->data, k->size, &sk, &e) == MLOD_OK) {
			joints = sk.joint_count;
			mlod_pack_skeleton_free(&sk);
		}
		if (n != 3 || tag[0] != MLOD_STREAM_KEPT || tag[1] != MLOD_STREAM_PALR || tag[2] != MLOD_STREAM_PALX ||
		    h[10] != MLOD_SCODEC_RAW || h[16 + 10] != MLOD_SCODEC_RAW || !joints || !count[0] || !count[1]) {
			free(d);
			d = NULL;
		} else {
			uint8_t *kept = b + 4 + 16 * 3, *palr = kept + 4 * (size_t)count[0]; /* 4-byte records: no padding */
			uint32_t v;
			switch (what) {
			case 0: memcpy(kept + 4 * ((size_t)count[0] - 1), &joints, 4); break;
			case 1: v = count[0] + 1, memcpy(h + 4, &v, 4); break;
			case 2: v = count[1] + count[2] + 1, memcpy(palr, &v, 4); break;
			default:
				v = p.chunks[c].raw_size + 4;
				memcpy(d + 32 + 48 * (size_t)c + 28, &v, 4);
				break;
			}
			fix_crcs(d, &p, c);
		}
	}
	mlod_pack_close(&p);
	return d;
}

TEST(hostile_skeleton_claims_fail_the_level)
{
	SKIP_IF_NO_PACK(hostile_skeleton_claims_fail_the_level);
	CHECK(packs_ready(), "mlod-pack failed");
	const struct pk *k = &packs[RAW];
	/* room for the level's true size and more; no room at all (the records
	 * are checked before room is asked: they fail it, not the budget) */
	for (int what = 0; what < 4; what++)
		for (int how = 0; how < 4; how++) {
			const int read = how & 1;
			const size_t extra = how & 2 ? 0 : 20000;
			uint8_t *d = skel_edited(what);
			CHECK(d, "no raw 'KEPT', 'PALR', 'PALX' streams in skeleton level 1");
			const struct pk ed = { k->sample, k->opts, k->file, "", d, k->size };
			mlod_error e = { 0 };
			mlod_rt_ctx *ctx = NULL;
			rt_mem_source src;
			size_t need = 0;
			CHECK_OK(mlod_rt_open_memory_bytes(d, k->size, NULL, &need, &e), e);
			if (read)
				CHECK_OK(mlod_rt_open_read_bytes(rt_mem_read, &(rt_mem_source){ d, k->size, 0, 0 }, k->size, NULL, &need, &e), e);
			CHECK_OK(open_how(&ed, read, &src, need + extra, &ctx, &e), e);
			CHECK_OK(mlod_rt_request(ctx, MLOD_RT_SKELETON, 1, 0, &e), e);
			mlod_result r = mlod_rt_stream(ctx, SIZE_MAX, NULL, &e);
			CHECK(r == MLOD_ERR_PARSE, "edit %d (%s, %zu bytes of room): %s: %s", what, read ? "read" : "memory",
			      extra, mlod_strerror(r), e.message);
			mlod_rt_level_info li;
			CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_SKELETON, 1, 0, &li, &e), e);
			mlod_rt_stats st;
			mlod_rt_stats_get(ctx, &st);
			CHECK(li.failed && !li.resident && !li.no_room && st.resident_bytes <= st.budget_bytes &&
			              st.peak_resident_bytes <= st.budget_bytes,
			      "edit %d: failed %d, resident %d, no_room %d; resident bytes %zu, peak %zu, budget %zu", what,
			      li.failed, li.resident, li.no_room, st.resident_bytes, st.peak_resident_bytes, st.budget_bytes);
			/* its wants passed to the coarsest, resident from open */
			CHECK_OK(mlod_rt_level_info_get(ctx, MLOD_RT_SKELETON, 2, 0, &li, &e), e);
			CHECK(li.resident, "skeleton level 2 not resident in place of the failed level 1");
			mlod_rt_close(ctx);
			free(d);
		}
}

TEST(open_bytes_is_the_least_budget)
{
	SKIP_IF_NO_PACK(open_bytes_is_the_least_budget);
	CHECK(packs_ready(), "mlod-pack failed");
	for (size_t p = 0; p < PACKS; p++) {
		const struct pk *k = &packs[p];
		mlod_error e = { 0 };
		size_t need[3] = { 0, 0, 0 };
		rt_mem_source src = { k->data, k->size, 0, 0 };
		mlod_rt_config big = { 1, 4, NULL }; /* its budget is ignored */
		CHECK_OK(mlod_rt_open_memory_bytes(k->data, k->size, &big, &need[0], &e), e);
		CHECK_OK(mlod_rt_open_path_bytes(k->path, NULL, &need[1], &e), e);
		CHECK_OK(mlod_rt_open_read_bytes(rt_mem_read, &src, k->size, NULL, &need[2], &e), e);
		CHECK(need[0] > 0 && need[1] > need[0] && need[1] == need[2],
		      "%s: memory %zu, path %zu, read %zu (the staging buffer beyond memory's)", k->file, need[0], need[1],
		      need[2]);
		for (int how = 0; how < 3; how++)
			for (int less = 0; less < 2; less++) {
				mlod_rt_config cfg = { need[how] - (size_t)less, 4, NULL };
				mlod_rt_ctx *ctx = NULL;
				mlod_result r = how == 0   ? mlod_rt_open_memory(k->data, k->size, &cfg, &ctx, &e)
				                : how == 1 ? mlod_rt_open_path(k->path, &cfg, &ctx, &e)
				                           : mlod_rt_open_read(rt_mem_read, &src, k->size, &cfg, &ctx, &e);
				CHECK(r == (less ? MLOD_ERR_LIMIT : MLOD_OK), "%s, open %d under %zu: %s: %s", k->file, how,
				      cfg.budget_bytes, mlod_strerror(r), e.message);
				if (r == MLOD_OK) {
					mlod_rt_stats st;
					mlod_rt_stats_get(ctx, &st);
					CHECK(st.open_bytes == need[how] && st.resident_bytes == need[how],
					      "%s: open_bytes %zu, resident %zu, asked %zu", k->file, st.open_bytes,
					      st.resident_bytes, need[how]);
				}
				mlod_rt_close(ctx);
			}
		/* the opens' errors, and a NULL bytes */
		size_t b = 1;
		CHECK(mlod_rt_open_memory_bytes(k->data, k->size / 2, NULL, &b, &e) == MLOD_ERR_PARSE && b == 0,
		      "%s: half a pack: %s, %zu bytes", k->file, e.message, b);
		CHECK(mlod_rt_open_path_bytes("/nonexistent/x.mlod", NULL, &b, &e) == MLOD_ERR_IO && b == 0,
		      "a missing path: %s", e.message);
		CHECK(mlod_rt_open_memory_bytes(k->data, k->size, NULL, NULL, &e) == MLOD_ERR_INVALID_ARG,
		      "NULL bytes accepted");
		CHECK(mlod_rt_open_read_bytes(NULL, &src, k->size, NULL, &b, &e) == MLOD_ERR_INVALID_ARG && b == 0,
		      "NULL read accepted");
	}
}

int main(int argc, char **argv)
{
	(void)argc;
	static const char *const samples[] = { "samples/tubeman.glb", "samples/RobotExpressive.glb",
		                               "samples/cmu_12_01_walk.bvh", NULL };
	rt_packer_setup(argv[0], "rt_budget", samples);
	RUN(level_loads_in_its_size);
	RUN(ely_levels_load_in_their_size);
	RUN(hostile_motion_claims_fail_the_level);
	RUN(hostile_skeleton_claims_fail_the_level);
	RUN(open_bytes_is_the_least_budget);
	for (size_t p = 0; p < PACKS; p++)
		free(packs[p].data);
	rt_packer_cleanup();
	TEST_EXIT();
}
