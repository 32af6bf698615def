/*
 * packdoc.c: the copy of the input document that the DOC chunk keeps,
 * stripped of what the pack's other chunks hold (packwrite_internal.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pack/packwrite_internal.h"

/* ------------------------------------------------------------------ */
/* The document the DOC chunk keeps                                   */
/* ------------------------------------------------------------------ */

/* The DOC's asset extras.mlod when joint nodes' TRS went, by mode
 * (mlod_gltf_drop_node_trs); mlod_pack_unpack reads it back. */
static const char *const trs_marks[3] = {"{\"doc_trs\":0}", "{\"doc_trs\":1}", "{\"doc_trs\":2}"};

/* A skin's inverse bind matrices are all identities (glTF's default). */
static int identity_binds(const mlod_skin *sk)
{
	mlod_mat4 id = mlod_mat4_identity();
	for (int j = 0; sk->inverse_bind && j < sk->joint_count; j++)
		if (memcmp(&sk->inverse_bind[j], &id, sizeof id) != 0)
			return 0;
	return 1;
}

/* Whether glTF index g is among the n in list. */
static int listed(const int *list, int n, int g)
{
	for (int i = 0; i < n; i++)
		if (list[i] == g)
			return 1;
	return 0;
}

/* The copy of the document that the DOC chunk strips. A BVH's document,
 * which mlod_load builds in memory, is copied as the glb a stage writes of
 * it is read (written and read back): stripped, a document that was read
 * keeps the top-level arrays its edits empty ("accessors": [] ...), one
 * built writes none, and the walk packed alone and after mlod-label had
 * DOC chunks of 614 and 649 bytes. */
mlod_result pack_doc_copy(const struct ctx *x, const mlod_gltf *doc, mlod_gltf **copy, mlod_error *err)
{
	if (x->format != MLOD_FORMAT_BVH)
		return mlod_gltf_copy(doc, copy, err);
	void *glb = NULL;
	size_t size = 0;
	mlod_result r = mlod_gltf_write(doc, 1, &glb, &size, err);
	if (r == MLOD_OK)
		r = mlod_gltf_read(glb, size, NULL, copy, err);
	mlod_free(glb);
	return r;
}

/* A piped input's level nodes (every MSFT_lod entry of x->doc, and the
 * nodes a level skin skins: mlod-skelgraph's), their meshes and the level
 * skins, each listed once; ln and lm hold a node count, ls a skin count. */
static void level_refs(const struct ctx *x, int *ln, int *nln_out, int *lm, int *nlm_out, int *ls, int *nls_out)
{
	const mlod_skeleton *s = &x->in->skeleton;
	const int nn = mlod_gltf_count(x->doc, MLOD_GLTF_NODE);
	int nln = 0, nlm = 0, nls = 0;
	for (int n = 0; n < nn; n++) {
		int ids[64], count = 0;
		mlod_error ignored = {0};
		if (mlod_gltf_node_lod(x->doc, n, ids, 64, &count, &ignored) != MLOD_OK)
			continue;
		for (int i = 0; i < count && i < 64; i++) {
			int mesh = -1, skin = -1;
			if (ids[i] == n || listed(ln, nln, ids[i]))
				continue;
			ln[nln++] = ids[i];
			if (mlod_gltf_node_refs(x->doc, ids[i], &mesh, &skin, &ignored) == MLOD_OK && mesh >= 0 &&
			    !listed(lm, nlm, mesh))
				lm[nlm++] = mesh;
		}
	}
	for (int i = 0; i < s->skin_count; i++)
		if (x->view_skin[i] < 0 && s->skins[i].gltf_index >= 0)
			ls[nls++] = s->skins[i].gltf_index;
	/* and the nodes a level skin skins (mlod-skelgraph's skeleton level
	 * nodes), with their meshes */
	for (int n = 0; nls > 0 && n < nn; n++) {
		int mesh = -1, skin = -1;
		mlod_error ignored = {0};
		if (mlod_gltf_node_refs(x->doc, n, &mesh, &skin, &ignored) != MLOD_OK || !listed(ls, nls, skin))
			continue;
		if (!listed(ln, nln, n))
			ln[nln++] = n;
		if (mesh >= 0 && !listed(lm, nlm, mesh))
			lm[nlm++] = mesh;
	}
	*nln_out = nln, *nlm_out = nlm, *nls_out = nls;
}

/* Which meshes of doc (a copy of x->doc, its indices the same, or a
 * BVH's document) the DOC chunk strips (mlod_gltf_strip_levels): a flag
 * per mesh, 1 for a mesh an instance of the character holds with a
 * surface (mlod_mesh_has_surface; its MESH parts give it back, where a
 * mesh without one has no part), a piped input's level mesh (the levels
 * replace it) or a mesh no node uses (-x writes none); any other mesh
 * (on a node outside the default scene, or shown without a surface)
 * keeps its triangle lists whole, with a warning for the former.
 * *flags is malloc'd. */
mlod_result pack_doc_strip_flags(struct ctx *x, const mlod_gltf *doc, unsigned char **flags, mlod_error *err)
{
	const mlod_character *c = x->in;
	const int nm = mlod_gltf_count(doc, MLOD_GLTF_MESH);
	unsigned char *f = calloc((size_t)nm + 1, 1);
	if (!f)
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	for (int i = 0; i < c->instance_count; i++) {
		const int m = c->instances[i].mesh;
		if (m >= 0 && m < c->mesh_count && c->meshes[m].gltf_index >= 0 && c->meshes[m].gltf_index < nm)
			f[c->meshes[m].gltf_index] = mlod_mesh_has_surface(&c->meshes[m]) ? 1 : 2;
	}
	if (x->doc) {
		const int nn = mlod_gltf_count(doc, MLOD_GLTF_NODE);
		int *ln = malloc(sizeof(int) * ((size_t)nn + 1)), *lm = malloc(sizeof(int) * ((size_t)nn + 1));
		int *ls = malloc(sizeof(int) * ((size_t)c->skeleton.skin_count + 1)), nln = 0, nlm = 0, nls = 0;
		if (!ln || !lm || !ls) {
			free(ln), free(lm), free(ls), free(f);
			return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
		}
		level_refs(x, ln, &nln, lm, &nlm, ls, &nls);
		for (int i = 0; i < nlm; i++)
			if (lm[i] >= 0 && lm[i] < nm)
				f[lm[i]] = 1;
		/* MSFT_lod levels without a stage record of levels are the
		 * input's own: the DOC chunk keeps MSFT_lod of no node
		 * (mlod_gltf_strip_levels), so they go; said, not silent. */
		if (nln > 0 && x->rec.mesh_level_count == 0 && x->rec.skel_level_count == 0) {
			char list[80] = "", text[200];
			mlod_int_list(list, sizeof list, ln, nln, 8);
			snprintf(text, sizeof text, "the input's own MSFT_lod level node%s %s %s not kept: the pack's levels "
			         "replace %s", nln > 1 ? "s" : "", list, nln > 1 ? "are" : "is", nln > 1 ? "them" : "it");
			pack_warn(x, text);
		}
		free(ln), free(lm), free(ls);
	}
	/* A mesh no node uses goes as the others do (-x writes no such mesh):
	 * no bytes kept for it. */
	unsigned char *used = calloc((size_t)nm + 1, 1);
	if (!used) {
		free(f);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	for (int n = 0; n < mlod_gltf_count(doc, MLOD_GLTF_NODE); n++) {
		int mesh = -1, skin = -1;
		mlod_error ignored = {0};
		if (mlod_gltf_node_refs(doc, n, &mesh, &skin, &ignored) == MLOD_OK && mesh >= 0 && mesh < nm)
			used[mesh] = 1;
	}
	for (int m = 0; m < nm; m++)
		if (!used[m])
			f[m] = 1;
	free(used);
	int whole = 0, first[12];
	for (int m = 0; m < nm; m++) {
		int triangles = 0;
		for (int p = 0; !f[m] && !triangles; p++) {
			char **names = NULL;
			int count = 0, mode = 4;
			mlod_error e = {0};
			mlod_result r = mlod_gltf_primitive_attributes(doc, m, p, &mode, &names, &count, &e);
			if (r == MLOD_ERR_NOMEM) {
				free(f);
				return mlod_fail(err, r, "%s", e.message);
			}
			if (r != MLOD_OK) /* past the mesh's last primitive */
				break;
			mlod_free(names);
			triangles = mode == 4;
		}
		if (f[m] == 2) /* shown, but no surface: whole, as the mesh layer leaves it */
			f[m] = 0;
		else if (triangles && whole++ < 12)
			first[whole - 1] = m;
	}
	if (whole) {
		char list[120] = "", text[320];
		mlod_int_list(list, sizeof list, first, whole, 12);
		snprintf(text, sizeof text, "mesh%s %s %s on no node of the default scene: the document chunk keeps %s "
		         "whole, without levels", whole > 1 ? "es" : "", list, whole > 1 ? "are" : "is",
		         whole > 1 ? "them" : "it");
		pack_warn(x, text);
	}
	*flags = f;
	return MLOD_OK;
}

/* The stripped DOC without what the other chunks hold (mlod(5) DOC):
 * the inverse bind matrices of the packed skins (SKEL holds them; not
 * identities), the joint nodes' translation, rotation and scale that are
 * SKEL's rest TRS at f32 (not the defaults), the stages' records
 * (extras "mlod", but for a BVH's End Site marks, "end_site", which are
 * the input's), and a piped input's levels: its level animations, and
 * its level nodes (MSFT_lod entries, nodes with a level skin), level
 * skins and level meshes when they are the last of their kind (as the
 * stages append them; else they stay, with a note). */
mlod_result pack_doc_dedupe(struct ctx *x, mlod_gltf *copy, int whole, mlod_error *err)
{
	const mlod_character *c = x->in;
	const mlod_skeleton *s = &c->skeleton;
	mlod_result r = MLOD_OK;
	for (int i = 0; r == MLOD_OK && !whole && i < x->v.skeleton.skin_count; i++) {
		const mlod_skin *sk = &x->v.skeleton.skins[i];
		if (sk->gltf_index >= 0 && x->v.skeleton.joint_count > 0 && !identity_binds(sk))
			r = mlod_gltf_drop_inverse_binds(copy, sk->gltf_index, err);
	}
	/* The joints' nodes' rest TRS (SKEL's JNTS hold it, as f32) when their
	 * numbers are those of the f32 values (mode 0), their shortest
	 * decimals (1) or their 15 significant digits (2), whichever more
	 * parts use (the asset's extras.mlod.doc_trs says which). */
	int parts[3] = {0, 0, 0}, nodes = mlod_gltf_count(copy, MLOD_GLTF_NODE);
	for (int mode = 0; mode < 3 && !whole; mode++)
		for (int j = 0; r == MLOD_OK && j < x->v.skeleton.joint_count; j++) {
			const mlod_joint *q = &x->v.skeleton.joints[j];
			int d = 0;
			if (q->node >= 0 && q->node < nodes)
				r = mlod_gltf_drop_node_trs(copy, q->node, &q->rest, mode, 0, &d, err);
			parts[mode] += (d & 1) + (d >> 1 & 1) + (d >> 2 & 1);
		}
	int trs_mode = parts[1] > parts[0] ? 1 : 0;
	trs_mode = parts[2] > parts[trs_mode] ? 2 : trs_mode;
	for (int j = 0; r == MLOD_OK && parts[trs_mode] > 0 && j < x->v.skeleton.joint_count; j++) {
		const mlod_joint *q = &x->v.skeleton.joints[j];
		if (q->node >= 0 && q->node < nodes)
			r = mlod_gltf_drop_node_trs(copy, q->node, &q->rest, trs_mode, 1, NULL, err);
	}
	static const mlod_gltf_kind kinds[] = {MLOD_GLTF_NODE, MLOD_GLTF_SKIN, MLOD_GLTF_SCENE, MLOD_GLTF_MESH,
	                                       MLOD_GLTF_ANIMATION};
	for (size_t k = 0; r == MLOD_OK && k < sizeof kinds / sizeof *kinds; k++)
		for (int i = 0; r == MLOD_OK && i < mlod_gltf_count(copy, kinds[k]); i++)
			r = mlod_gltf_remove_extra(copy, kinds[k], i, "mlod", "end_site", err);
	if (r == MLOD_OK)
		r = mlod_gltf_remove_extra(copy, MLOD_GLTF_ASSET, 0, "mlod", "end_site", err);
	if (r == MLOD_OK && parts[trs_mode] > 0)
		r = mlod_gltf_set_extra(copy, MLOD_GLTF_ASSET, 0, "mlod", trs_marks[trs_mode], err);
	/* The level animations (those strip_levels left: morph weights, other
	 * nodes' channels); a document whose indices hold (whole), from the
	 * last animation down while they are levels. */
	int anims = mlod_gltf_count(copy, MLOD_GLTF_ANIMATION), dropped = 0, levels = 0;
	for (int a = anims - 1; r == MLOD_OK && a >= 0; a--) {
		int level = 0;
		for (int i = 0; !level && i < c->clip_count; i++) {
			int in_v = 0;
			for (int q = 0; q < x->v.clip_count; q++)
				in_v |= x->v.clips[q].name == c->clips[i].name;
			level = !in_v && c->clips[i].name && mlod_gltf_find_animation(copy, c->clips[i].name, 0) == a;
		}
		levels += level;
		if (level && (!whole || a + dropped + 1 == anims)) {
			r = mlod_gltf_drop_animation(copy, a, err);
			dropped++;
		}
	}
	if (r == MLOD_OK && dropped < levels)
		pack_note(x, "the document chunk keeps some of the input's level animations: they are not its last animations");
	if (r != MLOD_OK || !x->doc)
		return r;
	/* The level nodes (every MSFT_lod entry), their meshes, level skins. */
	int nn = mlod_gltf_count(x->doc, MLOD_GLTF_NODE), ns = mlod_gltf_count(x->doc, MLOD_GLTF_SKIN),
	    nm = mlod_gltf_count(x->doc, MLOD_GLTF_MESH);
	int *ln = malloc(sizeof(int) * ((size_t)nn + 1)), *lm = malloc(sizeof(int) * ((size_t)nn + 1));
	int *ls = malloc(sizeof(int) * ((size_t)s->skin_count + 1)), nln = 0, nlm = 0, nls = 0;
	if (!ln || !lm || !ls) {
		free(ln), free(lm), free(ls);
		return mlod_fail(err, MLOD_ERR_NOMEM, "out of memory");
	}
	level_refs(x, ln, &nln, lm, &nlm, ls, &nls);
	/* Each kind from its first level one on, when all of those are. */
	int from[3] = {nn, ns, nm}, *lists[3] = {ln, ls, lm}, counts[3] = {nln, nls, nlm}, totals[3] = {nn, ns, nm};
	for (int k = 0; k < 3; k++) {
		int f = totals[k];
		while (f > 0 && listed(lists[k], counts[k], f - 1))
			f--;
		from[k] = f;
	}
	/* a mesh a kept node still uses stays (drop_tail refuses it) */
	if (from[0] < nn || from[1] < ns || from[2] < nm) {
		mlod_error derr = {0};
		mlod_result dr = mlod_gltf_drop_tail(copy, from[0], from[1], from[2], &derr);
		if (dr == MLOD_ERR_UNSUPPORTED) {
			char text[MLOD_ERROR_MESSAGE_SIZE + 64];
			snprintf(text, sizeof text, "the document chunk keeps the input's level nodes: %s", derr.message);
			pack_note(x, text);
		} else if (dr != MLOD_OK) {
			r = mlod_fail(err, dr, "%s", derr.message);
		}
	}
	if (r == MLOD_OK && (nln > 0 && from[0] > nn - nln))
		pack_note(x, "the document chunk keeps some of the input's level nodes: they are not its last nodes");
	free(ln), free(lm), free(ls);
	return r;
}
