// test_openmesh.cpp: checks every mesh level mlod makes with OpenMesh, an
// independent half-edge implementation (the only C++ test of mlod).
//
// For every sample (and ../shared/data with make test-extended), every
// triangle primitive of every mesh node is simplified as mlod-bgm does by
// default (triangle and edge collapses, posed cost), with triangle
// collapses only, and with the paper's compactness cost; each level (50%,
// 25%, 10% of the triangles) is loaded into an OpenMesh TriMesh after
// welding by position (else UV seams would count as borders). A level
// passes when, compared with the input primitive loaded the same way:
// - OpenMesh refuses no more faces (add_face returns an invalid handle for
//   a face that would make an edge or vertex non-manifold);
// - it has no more non-manifold vertices and no more boundary edges;
// - it has no degenerate face (two corners at one position, or zero area).
// Prints one PASS/FAIL line per sample, cost and level, like test.h.
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "mlod.h"

typedef OpenMesh::TriMesh_ArrayKernelT<> Mesh;

namespace {

struct Counts {
	int faces = 0;
	int refused = 0;
	int degenerate = 0;
	int nonmanifold_vertices = 0;
	int boundary_edges = 0;
};

Counts check(const mlod_primitive &p)
{
	Counts c;
	Mesh mesh;
	std::map<std::array<float, 3>, Mesh::VertexHandle> weld;
	std::vector<Mesh::VertexHandle> vh(size_t(p.vertex_count));
	for (int v = 0; v < p.vertex_count; v++) {
		std::array<float, 3> key = {p.positions[3 * v], p.positions[3 * v + 1], p.positions[3 * v + 2]};
		auto it = weld.find(key);
		if (it == weld.end())
			it = weld.emplace(key, mesh.add_vertex(Mesh::Point(key[0], key[1], key[2]))).first;
		vh[size_t(v)] = it->second;
	}
	int n = p.index_count > 0 ? p.index_count : p.vertex_count;
	for (int t = 0; t + 2 < n; t += 3) {
		Mesh::VertexHandle f[3];
		for (int k = 0; k < 3; k++)
			f[k] = vh[p.index_count > 0 ? p.indices[t + k] : uint32_t(t + k)];
		c.faces++;
		Mesh::Point a = mesh.point(f[0]), b = mesh.point(f[1]), d = mesh.point(f[2]);
		if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || ((b - a) % (d - a)).sqrnorm() == 0.0f) {
			c.degenerate++;
			continue;
		}
		if (!mesh.add_face(f[0], f[1], f[2]).is_valid())
			c.refused++;
	}
	for (auto v : mesh.vertices())
		if (!mesh.is_isolated(v) && !mesh.is_manifold(v))
			c.nonmanifold_vertices++;
	for (auto e : mesh.edges())
		if (mesh.is_boundary(e))
			c.boundary_edges++;
	return c;
}

void *read_file(const char *path, size_t *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return nullptr;
	std::vector<char> buf;
	char chunk[65536];
	size_t got;
	while ((got = fread(chunk, 1, sizeof chunk, f)) > 0)
		buf.insert(buf.end(), chunk, chunk + got);
	fclose(f);
	void *out = malloc(buf.size() + 1);
	if (out)
		memcpy(out, buf.data(), buf.size());
	*size = buf.size();
	return out;
}

int failures = 0;

void report(const std::string &name, const std::string &problem)
{
	if (problem.empty()) {
		printf("PASS %s\n", name.c_str());
	} else {
		printf("FAIL %s: %s\n", name.c_str(), problem.c_str());
		failures++;
	}
	fflush(stdout);
}

void check_sample(const char *path, const char *label)
{
	const double ratios[] = {0.5, 0.25, 0.1};
	const mlod_mesh_cost costs[] = {MLOD_COST_POSED, MLOD_COST_POSED, MLOD_COST_COMPACTNESS};
	const mlod_collapse_op ops[] = {MLOD_OP_MIXED, MLOD_OP_TRIANGLE, MLOD_OP_TRIANGLE};
	const char *cost_names[] = {"posed", "posed-triangle", "compactness"};
	size_t size = 0;
	void *data = read_file(path, &size);
	mlod_character c;
	mlod_error err;
	memset(&c, 0, sizeof c);
	if (!data || mlod_load(data, size, nullptr, nullptr, &c, nullptr, &err) != MLOD_OK) {
		report(std::string(label) + "/load", data ? err.message : "cannot read");
		free(data);
		return;
	}
	free(data);
	mlod_pose_set poses;
	int clips = c.clip_count > 0 ? c.clip_count : 1, per_clip = std::max(2, std::min(8, 24 / clips));
	if (mlod_pose_set_make(&c, 0, per_clip, 8, 1, 0.6981317f, &poses, &err) != MLOD_OK) {
		report(std::string(label) + "/poses", err.message);
		mlod_character_free(&c);
		return;
	}
	for (int ci = 0; ci < 3; ci++) {
		std::string problems[3];
		int primitives = 0, collapsed[3] = {0, 0, 0};
		for (int i = 0; i < c.instance_count; i++) {
			const mlod_mesh &m = c.meshes[c.instances[i].mesh];
			if (c.instances[i].skin < 0 && c.instances[i].joint < 0)
				continue; /* left as they are */
			for (int pi = 0; pi < m.primitive_count; pi++) {
				const mlod_primitive &p = m.primitives[pi];
				if (p.mode != 4)
					continue;
				Counts in = check(p);
				mlod_bgm_options opt;
				memset(&opt, 0, sizeof opt);
				opt.cost = costs[ci];
				opt.op = ops[ci];
				opt.poses = &poses;
				mlod_bgm *g = nullptr;
				if (mlod_bgm_build(&c, i, pi, &opt, &g, &err) != MLOD_OK ||
				    mlod_bgm_simplify(g, int(std::ceil(0.1 * in.faces)), 0, &err) != MLOD_OK) {
					problems[0] = std::string("instance ") + std::to_string(i) + ": " + err.message;
					mlod_bgm_free(g);
					continue;
				}
				primitives++;
				for (int k = 0; k < 3; k++) {
					int prefix = mlod_bgm_prefix_for(g, int(std::ceil(ratios[k] * in.faces)));
					mlod_primitive q;
					if (mlod_bgm_extract(g, prefix, 1, &q, &err) != MLOD_OK) {
						problems[k] = err.message;
						continue;
					}
					collapsed[k] += prefix;
					Counts out = check(q);
					mlod_primitive_free(&q);
					char why[256] = "";
					if (out.refused > in.refused)
						snprintf(why, sizeof why, "instance %d primitive %d: %d faces refused (input %d)", i, pi, out.refused,
						         in.refused);
					else if (out.nonmanifold_vertices > in.nonmanifold_vertices)
						snprintf(why, sizeof why, "instance %d primitive %d: %d non-manifold vertices (input %d)", i, pi,
						         out.nonmanifold_vertices, in.nonmanifold_vertices);
					else if (out.boundary_edges > in.boundary_edges)
						snprintf(why, sizeof why, "instance %d primitive %d: %d boundary edges (input %d)", i, pi,
						         out.boundary_edges, in.boundary_edges);
					else if (out.degenerate > 0)
						snprintf(why, sizeof why, "instance %d primitive %d: %d degenerate faces", i, pi, out.degenerate);
					if (why[0] && problems[k].empty())
						problems[k] = why;
				}
				mlod_bgm_free(g);
			}
		}
		for (int k = 0; k < 3; k++) {
			if (problems[k].empty() && (primitives == 0 || collapsed[k] == 0))
				problems[k] = "nothing was simplified, so nothing was checked";
			char name[256];
			snprintf(name, sizeof name, "%s/%s/level%d", label, cost_names[ci], k + 1);
			report(name, problems[k]);
		}
	}
	mlod_pose_set_free(&poses);
	mlod_character_free(&c);
}

} // namespace

int main()
{
	omerr().disable(); /* "complex edge" messages: counted, not printed */
	omlog().disable();
	check_sample("samples/tubeman.glb", "tubeman");
	check_sample("samples/RobotExpressive.glb", "RobotExpressive");
	const char *shared = getenv("MLOD_SHARED_DATA");
	if (shared && *shared) {
		std::string ely = std::string(shared) + "/Ely.glb";
		check_sample(ely.c_str(), "Ely");
	}
	return failures ? 1 : 0;
}
