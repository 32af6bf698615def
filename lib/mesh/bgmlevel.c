/*
 * bgmlevel.c: mesh levels from the recorded collapse sequence (Savoye &
 * Meyer 2008, 4.2, step 4: "given a LoD threshold, we do a
 * triangle-collapse operation on triangles that meet the threshold in the
 * sequence ... and we undo the triangle-collapse operation on others").
 *
 * The faces live after the first k collapses are those born at or before
 * record k and not removed by it or earlier; their wedges become the
 * level's vertices. An input vertex keeps all its attributes exactly; a
 * vertex a collapse made gets its wedge's interpolated attributes, its
 * node's morph target offsets and its node's Power Skinning influences
 * (at most 4, in weight set 0).
 */
#include <stdlib.h>
#include <string.h>

#include "bgm.h"

static int live_at(const bgm_face *f, int prefix)
{
	return f->birth <= prefix && f->death > prefix;
}

mlod_result mlod_bgm_extract(const mlod_bgm *g, int prefix, int rigid_as_skinned, mlod_primitive *out,
                             mlod_error *err)
{
	if (!g || !out)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_bgm_extract: NULL argument");
	memset(out, 0, sizeof *out);
	if (prefix < 0 || prefix > g->record_count)
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "prefix %d: the sequence has %d collapses", prefix,
		                 g->record_count);
	const mlod_primitive *src = g->prim;
	const bgm_layout *L = &g->lay;
	int *map = malloc(sizeof(int) * ((size_t)g->wedge_count + 1));
	if (!map)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory extracting a level");
	for (int w = 0; w < g->wedge_count; w++)
		map[w] = -1;
	int faces = 0;
	for (int f = 0; f < g->face_count; f++)
		if (live_at(&g->faces[f], prefix)) {
			faces++;
			for (int k = 0; k < 3; k++)
				map[g->faces[f].w[k]] = 0;
		}
	int n = 0;
	for (int w = 0; w < g->wedge_count; w++)
		if (map[w] == 0)
			map[w] = n++;

	mlod_primitive *p = out;
	size_t N = (size_t)(n > 0 ? n : 1);
	p->vertex_count = n;
	p->mode = 4;
	p->material = src->material;
	p->index_count = 3 * faces;
	p->uv_set_count = src->uv_set_count;
	p->color_set_count = src->color_set_count;
	int sets = g->skinned ? src->weight_set_count : g->rigid && rigid_as_skinned ? 1 : 0;
	p->weight_set_count = sets;
	int failed = !(p->positions = malloc(sizeof(float) * 3 * N));
	failed |= !(p->indices = malloc(sizeof(uint32_t) * (size_t)(p->index_count > 0 ? p->index_count : 1)));
	if (src->normals)
		failed |= !(p->normals = malloc(sizeof(float) * 3 * N));
	if (src->tangents)
		failed |= !(p->tangents = malloc(sizeof(float) * 4 * N));
	for (int k = 0; k < MLOD_MAX_SETS; k++) {
		if (k < src->uv_set_count && src->uvs[k])
			failed |= !(p->uvs[k] = malloc(sizeof(float) * 2 * N));
		if (k < src->color_set_count && src->colors[k])
			failed |= !(p->colors[k] = malloc(sizeof(float) * 4 * N));
		if (k < sets) {
			failed |= !(p->joints[k] = calloc(4 * N, sizeof(uint16_t)));
			failed |= !(p->weights[k] = calloc(4 * N, sizeof(float)));
		}
	}
	if (src->target_count > 0) {
		p->target_count = src->target_count;
		failed |= !(p->targets = calloc((size_t)src->target_count, sizeof *p->targets));
		for (int t = 0; !failed && t < src->target_count; t++) {
			if (src->targets[t].positions)
				failed |= !(p->targets[t].positions = malloc(sizeof(float) * 3 * N));
			if (src->targets[t].normals)
				failed |= !(p->targets[t].normals = malloc(sizeof(float) * 3 * N));
			if (src->targets[t].tangents)
				failed |= !(p->targets[t].tangents = malloc(sizeof(float) * 3 * N));
		}
	}
	if (failed) {
		free(map);
		mlod_primitive_free(p);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory extracting a level");
	}

	for (int w = 0; w < g->wedge_count; w++) {
		int o = map[w];
		if (o < 0)
			continue;
		int s = g->wedge_source[w], node = g->wedge_node[w];
		const float *a = L->stride > 0 ? g->wedge_attr + (size_t)w * (size_t)L->stride : NULL;
		if (s >= 0) {
			/* An input vertex: everything as it was. */
			memcpy(p->positions + 3 * o, src->positions + 3 * s, 3 * sizeof(float));
			if (p->normals)
				memcpy(p->normals + 3 * o, src->normals + 3 * s, 3 * sizeof(float));
			if (p->tangents)
				memcpy(p->tangents + 4 * o, src->tangents + 4 * s, 4 * sizeof(float));
			for (int k = 0; k < MLOD_MAX_SETS; k++) {
				if (p->uvs[k])
					memcpy(p->uvs[k] + 2 * o, src->uvs[k] + 2 * s, 2 * sizeof(float));
				if (p->colors[k])
					memcpy(p->colors[k] + 4 * o, src->colors[k] + 4 * s, 4 * sizeof(float));
				if (k < sets && g->skinned) {
					memcpy(p->joints[k] + 4 * o, src->joints[k] + 4 * s, 4 * sizeof(uint16_t));
					memcpy(p->weights[k] + 4 * o, src->weights[k] + 4 * s, 4 * sizeof(float));
				}
			}
			for (int t = 0; t < p->target_count; t++) {
				if (p->targets[t].positions)
					memcpy(p->targets[t].positions + 3 * o, src->targets[t].positions + 3 * s, 3 * sizeof(float));
				if (p->targets[t].normals)
					memcpy(p->targets[t].normals + 3 * o, src->targets[t].normals + 3 * s, 3 * sizeof(float));
				if (p->targets[t].tangents)
					memcpy(p->targets[t].tangents + 3 * o, src->targets[t].tangents + 3 * s, 3 * sizeof(float));
			}
		} else {
			/* A vertex a collapse made. */
			for (int i = 0; i < 3; i++)
				p->positions[3 * o + i] = (float)g->nodes[node].p[i];
			if (p->normals)
				memcpy(p->normals + 3 * o, a + L->normal, 3 * sizeof(float));
			if (p->tangents)
				memcpy(p->tangents + 4 * o, a + L->tangent, 4 * sizeof(float));
			for (int k = 0; k < MLOD_MAX_SETS; k++) {
				if (p->uvs[k])
					memcpy(p->uvs[k] + 2 * o, a + L->uv[k], 2 * sizeof(float));
				if (p->colors[k])
					memcpy(p->colors[k] + 4 * o, a + L->color[k], 4 * sizeof(float));
			}
			if (sets > 0 && g->skinned) {
				const mlod_influences *inf = &g->inf[node];
				for (int i = 0; i < inf->count && i < 4; i++) {
					p->joints[0][4 * o + i] = inf->joints[i];
					p->weights[0][4 * o + i] = inf->weights[i];
				}
			}
			const float *m = L->morph_stride > 0 ? g->morph + (size_t)node * (size_t)L->morph_stride : NULL;
			for (int t = 0; t < p->target_count; t++) {
				if (p->targets[t].positions)
					memcpy(p->targets[t].positions + 3 * o, m + 3 * t, 3 * sizeof(float));
				if (p->targets[t].normals)
					memcpy(p->targets[t].normals + 3 * o, a + L->target_normal + 3 * t, 3 * sizeof(float));
				if (p->targets[t].tangents)
					memcpy(p->targets[t].tangents + 3 * o, a + L->target_tangent + 3 * t, 3 * sizeof(float));
			}
		}
		if (g->rigid && sets > 0) {
			p->joints[0][4 * o] = 0;
			p->weights[0][4 * o] = 1.0f;
		}
	}
	int k = 0;
	for (int f = 0; f < g->face_count; f++)
		if (live_at(&g->faces[f], prefix))
			for (int i = 0; i < 3; i++)
				p->indices[k++] = (uint32_t)map[g->faces[f].w[i]];
	free(map);
	return MLOD_OK;
}

mlod_result mlod_primitive_remap_joints(mlod_primitive *p, const int *map, int map_count, mlod_error *err)
{
	if (!p || (!map && map_count > 0))
		return mlod_fail(err, MLOD_ERR_INVALID_ARG, "mlod_primitive_remap_joints: NULL argument");
	int sets = p->weight_set_count < MLOD_MAX_SETS ? p->weight_set_count : MLOD_MAX_SETS;
	for (int v = 0; v < p->vertex_count; v++) {
		mlod_influences x;
		memset(&x, 0, sizeof x);
		for (int s = 0; s < sets; s++)
			for (int k = 0; k < 4; k++) {
				float w = p->weights[s][4 * v + k];
				int j = p->joints[s][4 * v + k];
				if (!(w > 0.0f))
					continue;
				if (j >= map_count || map[j] < 0 || map[j] > 65535)
					return mlod_fail(err, MLOD_ERR_INVALID_ARG, "vertex %d: joint %d has no new index", v, j);
				int i = 0;
				while (i < x.count && x.joints[i] != map[j])
					i++;
				if (i == x.count) {
					x.joints[i] = (uint16_t)map[j];
					x.weights[i] = 0.0f;
					x.count++;
				}
				x.weights[i] += w;
			}
		/* Largest first. */
		for (int i = 1; i < x.count; i++) {
			uint16_t j = x.joints[i];
			float w = x.weights[i];
			int k = i;
			while (k > 0 && (x.weights[k - 1] < w || (x.weights[k - 1] == w && x.joints[k - 1] > j))) {
				x.joints[k] = x.joints[k - 1];
				x.weights[k] = x.weights[k - 1];
				k--;
			}
			x.joints[k] = j;
			x.weights[k] = w;
		}
		for (int s = 0; s < sets; s++)
			for (int k = 0; k < 4; k++) {
				int i = 4 * s + k;
				p->joints[s][4 * v + k] = i < x.count ? x.joints[i] : 0;
				p->weights[s][4 * v + k] = i < x.count ? x.weights[i] : 0.0f;
			}
	}
	return MLOD_OK;
}
