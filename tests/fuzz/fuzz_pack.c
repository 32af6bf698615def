/*
 * fuzz_pack.c: libFuzzer target for the pack reader and the runtime (make
 * fuzz; not part of make test). Each input is opened and every chunk
 * decoded, as the runtime would: INFO, SKELETON, then each skeleton level,
 * mesh level (codec meshopt, none or draco: the fuzz build links
 * lib/rt/rt_draco.cpp) and motion level against the decoded skeleton (or
 * without one), and DOC. Then the runtime opens the same bytes and
 * evaluates one frame at every level: an instance of each clip forced to
 * level k of every layer, mlod_rt_update, mlod_rt_stream, mlod_rt_pose,
 * mlod_rt_palette, mlod_rt_bounds (a finite skinned vertex outside its
 * box aborts), mlod_rt_skin and every joint's mlod_rt_joint_level_get.
 * A pack of format 8.1 or later states its largest mesh level's vertex
 * count (INFO's max_vertex_count): the skinning buffers are sized from it
 * once, at open, and a resident level of more vertices, a count that
 * changes after open or an mlod_rt_skin asking for more aborts; an older
 * pack's buffers grow as its levels load.
 *
 * The custom mutator (fuzz_restamp.h) re-stamps the CRCs on half of the
 * runs.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_restamp.h"
#include "mlod_pack.h"
#include "mlod_rt.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* At most this many levels per layer and clips are evaluated, and skinned
 * into at most this many vertices: a pack may list more, the runtime's
 * answers for them are no different in kind. */
enum { EVAL_LEVELS = 16, EVAL_CLIPS = 4, EVAL_VERTICES = 1 << 20 };

static void evaluate(const uint8_t *data, size_t size, int stated)
{
	mlod_rt_config cfg = {0, 8, NULL};
	mlod_rt_ctx *ctx = NULL;
	mlod_error e;
	if (mlod_rt_open_memory(data, size, &cfg, &ctx, &e) != MLOD_OK)
		return;
	uint32_t levels = 1;
	for (int l = 0; l < MLOD_RT_LAYERS; l++) {
		uint32_t n = mlod_rt_level_count(ctx, (mlod_rt_layer)l);
		if (n > levels)
			levels = n;
	}
	if (levels > EVAL_LEVELS)
		levels = EVAL_LEVELS;
	uint32_t clips = mlod_rt_clip_count(ctx);
	if (clips > EVAL_CLIPS)
		clips = EVAL_CLIPS;
	if (clips == 0)
		clips = 1;
	/* The buffers: sized once at open from the count the pack states, else
	 * grown to the largest level resident so far (up to EVAL_VERTICES;
	 * mlod_rt_skin refuses a larger one). */
	uint32_t cap = 0;
	float *pos = NULL, *nrm = NULL;
	const uint32_t at_open = mlod_rt_max_vertex_count(ctx);
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	if (s) {
		for (uint32_t clip = 0; clip < clips; clip++) {
			uint32_t id;
			if (mlod_rt_instance_create(ctx, clip, 0.25f, MLOD_RT_LOOP, &id, &e) != MLOD_OK)
				continue;
			for (uint32_t k = levels; k-- > 0;) {
				mlod_rt_select sel;
				mlod_rt_select_default(&sel);
				sel.force_level = (int)k;
				float d = 10.0f;
				mlod_rt_update(ctx, &sel, &id, &d, 1, 1.0f / 30, &e);
				mlod_rt_stream(ctx, (size_t)-1, NULL, &e);
				uint32_t want = mlod_rt_max_vertex_count(ctx);
				if (stated && want != at_open) /* known at open, never changed */
					abort();
				for (uint32_t m = 0; stated && m < mlod_rt_level_count(ctx, MLOD_RT_MESH); m++)
					if (mlod_rt_mesh_vertex_count(ctx, m) > at_open) /* a level past what INFO states */
						abort();
				want = want > EVAL_VERTICES ? EVAL_VERTICES : want;
				if (stated && pos && want > cap) /* sized at open: never grown */
					abort();
				if (want > cap || !pos) {
					free(pos);
					free(nrm);
					pos = malloc(((size_t)want + 1) * 3 * sizeof *pos);
					nrm = malloc(((size_t)want + 1) * 3 * sizeof *nrm);
					cap = pos && nrm ? want : 0;
				}
				const float *world;
				const uint32_t *joints;
				uint32_t jc, pc, vc;
				mlod_rt_pose(ctx, s, id, &world, &joints, &jc, &e);
				const float *pal;
				mlod_rt_palette(ctx, s, &pal, &pc, &e);
				float lo[3], hi[3];
				const int bounded = mlod_rt_bounds(ctx, s, id, lo, hi, &e) == MLOD_OK;
				const mlod_result sr = cap ? mlod_rt_skin(ctx, s, id, pos, 12, nrm, 12, cap, &vc, &e) : MLOD_ERR_LIMIT;
				if (sr == MLOD_OK && bounded)
					for (uint32_t v = 0; v < 3 * vc; v++) /* a finite vertex outside its box: abort */
						if (pos[v] == pos[v] && pos[v] - pos[v] == 0.0f && !(pos[v] >= lo[v % 3] && pos[v] <= hi[v % 3]))
							abort();
				if (sr == MLOD_ERR_LIMIT && stated && cap && at_open <= EVAL_VERTICES) /* more than INFO states */
					abort();
				mlod_rt_joint_level jl;
				for (uint32_t j = 0; j < mlod_rt_joint_count(ctx); j++)
					mlod_rt_joint_level_get(ctx, mlod_rt_instance_state(ctx, id)->level[MLOD_RT_SKELETON], j, &jl,
					                        &e);
			}
			mlod_rt_instance_destroy(ctx, id);
		}
	}
	if (s)
		mlod_rt_scratch_destroy(ctx, s);
	free(pos);
	free(nrm);
	mlod_rt_close(ctx);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	mlod_pack p;
	mlod_error e;
	if (mlod_pack_open(data, size, &p, &e) != MLOD_OK)
		return 0;
	mlod_pack_info info;
	mlod_pack_decode_info(&p, data, size, &info, &e);
	mlod_pack_info_free(&info);
	mlod_pack_skeleton skel;
	int have_skel = mlod_pack_decode_skeleton(&p, data, size, &skel, &e) == MLOD_OK;
	for (uint32_t i = 0; i < p.chunk_count; i++) {
		const mlod_pack_chunk *c = &p.chunks[i];
		if (c->type == MLOD_CHUNK_SKELETON && c->level > 0 && have_skel) {
			mlod_pack_skel_level l;
			mlod_pack_decode_skel_level(&p, i, data, size, &skel, &l, &e);
			mlod_pack_skel_level_free(&l);
		} else if (c->type == MLOD_CHUNK_MESH) {
			mlod_pack_mesh m;
			mlod_pack_decode_mesh(&p, i, data, size, have_skel ? &skel : NULL, &m, &e);
			mlod_pack_mesh_free(&m);
		} else if (c->type == MLOD_CHUNK_MOTION) {
			mlod_pack_motion m;
			mlod_pack_decode_motion(&p, i, data, size, have_skel ? &skel : NULL, &m, &e);
			mlod_pack_motion_free(&m);
		}
	}
	const void *glb;
	size_t glb_size;
	mlod_pack_doc(&p, data, size, &glb, &glb_size, &e);
	mlod_pack_doc_bytes doc;
	mlod_pack_decode_doc(&p, data, size, &doc, &e); /* also with the entropy stage */
	mlod_pack_doc_free(&doc);
	mlod_pack_skeleton_free(&skel);
	const int stated = mlod_pack_version_has_max_vertices(p.major, p.minor);
	mlod_pack_close(&p);
	evaluate(data, size, stated);
	return 0;
}
