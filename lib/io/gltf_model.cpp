/*
 * gltf_model.cpp: the document and the character model (gltf_internal.hpp).
 * glTF -> character: skins, meshes and animations decoded into the
 * structures of mlod_model.h (mlod_gltf_to_character). Character -> glTF:
 * meshes, skins, animations and nodes appended to a model
 * (mlod_gltf_from_character, mlod_gltf_add_*).
 */
#include "io/gltf_internal.hpp"

namespace mlod_gltf_internal {

/* ------------------------------------------------------------------ */
/* glTF -> character                                                   */
/* ------------------------------------------------------------------ */

namespace {

/* Builds an mlod_character from a document; every method may throw. */
class CharacterReader {
public:
	CharacterReader(const mlod_gltf &doc, mlod_character &c, std::vector<std::pair<int, int>> *fixed)
	    : doc_(doc), m_(doc.model), c_(c), fixed_(fixed)
	{
	}

	void read()
	{
		if (doc_.scene_added)
			note("the input has no scene: scene 0 added with its %d root node%s, for the stage record", doc_.scene_added,
			     doc_.scene_added == 1 ? "" : "s");
		if (doc_.rotations_normalised) {
			const tinygltf::Node &n = m_.nodes[size_t(doc_.rotation_node)];
			warn("%d node rotation%s normalised (not unit quaternions: node %d%s%s has length %g)",
			     doc_.rotations_normalised, doc_.rotations_normalised == 1 ? "" : "s", doc_.rotation_node,
			     n.name.empty() ? "" : " ", n.name.empty() ? "" : quoted(n.name).c_str(), doc_.rotation_length);
		}
		for (const std::string &u : doc_.unread_images)
			warn("%s: the output keeps its URI, which points at no image unless the file sits beside the output",
			     u.c_str());
		graph();
		skeleton();
		skins();
		meshes();
		instances();
		weights();
		clips();
		notes();
	}

private:
	const mlod_gltf &doc_;
	const Model &m_;
	mlod_character &c_;
	std::vector<std::pair<int, int>> *fixed_; /* the (mesh, primitive) pairs weights() changed; may be null */
	std::vector<int> parent_;       /* per node */
	std::vector<int> order_;        /* nodes, parents first */
	std::vector<mlod_mat4> local_;  /* per node */
	std::vector<mlod_mat4> world_;  /* per node, at rest */
	std::vector<int> joint_of_;     /* per node: joint index or -1 */
	std::vector<char> in_skin_;     /* per node */
	std::vector<char> animated_;    /* per node: a TRS channel targets it */
	std::vector<char> shown_;       /* per node: in the default scene */
	std::vector<std::string> notes_;
	std::vector<std::string> warnings_; /* the notes of what was changed or dropped */

	void vnote(bool warning, const char *fmt, va_list ap)
	{
		char buf[MLOD_ERROR_MESSAGE_SIZE];
		vsnprintf(buf, sizeof buf, fmt, ap);
		notes_.push_back(buf);
		if (warning)
			warnings_.push_back(buf);
	}

	/* A note for the report: what the reader read in its own way. */
	void note(const char *fmt, ...) __attribute__((format(printf, 2, 3)))
	{
		va_list ap;
		va_start(ap, fmt);
		vnote(false, fmt, ap);
		va_end(ap);
	}

	/* A note the tools also print on stderr: the reader changed,
	 * approximated or dropped something of the input. */
	void warn(const char *fmt, ...) __attribute__((format(printf, 2, 3)))
	{
		va_list ap;
		va_start(ap, fmt);
		vnote(true, fmt, ap);
		va_end(ap);
	}

	/* Parents, a parents-first order (depth-first from the roots, in file
	 * order), rest transforms, the nodes the default scene shows (without
	 * scenes, every node but the MSFT_lod levels other nodes name, and
	 * their children) and the nodes TRS channels animate. */
	void graph()
	{
		size_t n = m_.nodes.size();
		parent_ = node_parents(m_);
		std::vector<int> stack;
		for (size_t i = n; i-- > 0;)
			if (parent_[i] < 0)
				stack.push_back(int(i));
		while (!stack.empty()) {
			int k = stack.back();
			stack.pop_back();
			order_.push_back(k);
			const std::vector<int> &ch = m_.nodes[size_t(k)].children;
			for (size_t i = ch.size(); i-- > 0;)
				stack.push_back(ch[i]);
		}
		/* Depth, once per node (parents first). The stages after the
		 * reader walk joints to their roots (the rest box, the skeletal
		 * graph's closure edges, the motion checks over descendants): a
		 * hierarchy deeper than a BVH may be is refused, as the BVH
		 * reader refuses one. */
		std::vector<int> depth(n, 0);
		for (int k : order_) {
			int p = parent_[size_t(k)];
			depth[size_t(k)] = p < 0 ? 0 : depth[size_t(p)] + 1;
			if (depth[size_t(k)] >= MLOD_MAX_HIERARCHY_DEPTH)
				fail(MLOD_ERR_UNSUPPORTED, "node %d%s%s is %d levels deep: mlod reads node hierarchies at most %d levels "
				     "deep", k, m_.nodes[size_t(k)].name.empty() ? "" : " ",
				     m_.nodes[size_t(k)].name.empty() ? "" : quoted(m_.nodes[size_t(k)].name).c_str(), depth[size_t(k)] + 1,
				     MLOD_MAX_HIERARCHY_DEPTH);
		}
		local_.resize(n);
		world_.resize(n);
		for (int k : order_) {
			local_[size_t(k)] = node_matrix(m_.nodes[size_t(k)]);
			world_[size_t(k)] = parent_[size_t(k)] < 0 ? local_[size_t(k)]
			                                           : mlod_mat4_mul(&world_[size_t(parent_[size_t(k)])], &local_[size_t(k)]);
		}
		shown_.assign(n, 0);
		if (!m_.scenes.empty()) {
			for (int root : m_.scenes[size_t(std::max(m_.defaultScene, 0))].nodes)
				shown_[size_t(root)] = 1;
		} else { /* a document mlod built without a scene: every root but MSFT_lod levels */
			std::vector<char> level = lod_level_nodes(m_);
			for (size_t k = 0; k < n; k++)
				shown_[k] = parent_[k] < 0 && !level[k];
		}
		for (int k : order_)
			if (parent_[size_t(k)] >= 0 && shown_[size_t(parent_[size_t(k)])])
				shown_[size_t(k)] = 1;
		animated_.assign(n, 0);
		for (const tinygltf::Animation &a : m_.animations)
			for (const tinygltf::AnimationChannel &ch : a.channels)
				if (ch.target_node >= 0 && is_trs(ch.target_path))
					animated_[size_t(ch.target_node)] = 1;
	}

	static bool is_trs(const std::string &path)
	{
		return path == "translation" || path == "rotation" || path == "scale";
	}

	/* Is node n marked extras.mlod.end_site = true? */
	bool is_end_site(int n) const
	{
		const json e = current_extras(doc_, "/nodes/" + std::to_string(n) + "/extras", m_.nodes[size_t(n)].extras);
		const json none;
		const json &mlod = e.is_object() && e.contains(record_key) ? e[record_key] : none;
		return mlod.is_object() && mlod.contains(record_end_site) && mlod[record_end_site] == true;
	}

	/* A joint read from a BVH keeps its channel layout in
	 * extras.mlod_bvh.channels, so that its Euler order survives the glb. */
	void bvh_layout(int n, mlod_joint &j) const
	{
		static const char *const names[6] = {"Xposition", "Yposition", "Zposition",
		                                     "Xrotation", "Yrotation", "Zrotation"};
		const json e = current_extras(doc_, "/nodes/" + std::to_string(n) + "/extras", m_.nodes[size_t(n)].extras);
		if (!e.is_object() || !e.contains(bvh_key) || !e[bvh_key].is_object())
			return;
		const json &ch = e[bvh_key].contains(bvh_channels) ? e[bvh_key][bvh_channels] : json();
		if (!ch.is_array() || (ch.size() != 3 && ch.size() != 6))
			return;
		unsigned char codes[6];
		char axes[4] = {0};
		int rotations = 0;
		for (size_t i = 0; i < ch.size(); i++) {
			int code = -1;
			for (int k = 0; k < 6 && ch[i].is_string(); k++)
				if (ch[i].get<std::string>() == names[k])
					code = k;
			if (code < 0)
				return; /* not ours: ignore it */
			codes[i] = (unsigned char)code;
			if (code >= MLOD_BVH_XROT && rotations < 3)
				axes[rotations++] = char('X' + (code - MLOD_BVH_XROT));
		}
		mlod_euler_order order;
		if (rotations != 3 || mlod_euler_order_parse(axes, &order) != 0)
			return;
		j.channel_count = int(ch.size());
		memcpy(j.channels, codes, ch.size());
		j.euler = order;
	}

	/* Joints: skin joints and the nodes between a joint and its nearest
	 * joint ancestor, in parents-first order. A document without skins (a
	 * BVH converted to glTF, a node-animated rig) has its animated nodes
	 * instead of skin joints. Leaves marked as End Sites below a joint
	 * become that joint's End Site. */
	void skeleton()
	{
		size_t n = m_.nodes.size();
		in_skin_.assign(n, 0);
		for (const tinygltf::Skin &s : m_.skins)
			for (int j : s.joints)
				in_skin_[size_t(j)] = 1;
		const std::vector<char> &seeds = m_.skins.empty() ? animated_ : in_skin_;
		std::vector<char> is_joint(seeds);
		/* Nodes with no joint above them: a walk up stops there too, so
		 * that each node is walked through once (linear in the nodes, not
		 * seeds times depth). */
		std::vector<char> no_joint_above(n, 0);
		std::vector<int> between;
		for (size_t j = 0; j < n; j++) {
			if (!seeds[j])
				continue;
			between.clear();
			int k = parent_[j];
			while (k >= 0 && !is_joint[size_t(k)] && !no_joint_above[size_t(k)]) {
				between.push_back(k);
				k = parent_[size_t(k)];
			}
			bool joint_above = k >= 0 && is_joint[size_t(k)];
			for (int b : between)
				(joint_above ? is_joint : no_joint_above)[size_t(b)] = 1;
		}
		joint_of_.assign(n, -1);
		int count = 0;
		for (int k : order_)
			if (is_joint[size_t(k)])
				joint_of_[size_t(k)] = count++;
		mlod_skeleton &s = c_.skeleton;
		s.joints = c_array<mlod_joint>(size_t(count));
		s.joint_count = count;
		int sheared = 0;
		for (int k : order_) {
			int i = joint_of_[size_t(k)];
			if (i < 0)
				continue;
			mlod_joint &j = s.joints[i];
			const tinygltf::Node &node = m_.nodes[size_t(k)];
			j.name = c_string(node.name);
			j.node = k;
			j.euler = MLOD_EULER_XYZ;
			bvh_layout(k, j);
			int p = parent_[size_t(k)];
			j.parent = p >= 0 ? joint_of_[size_t(p)] : -1;
			j.base = j.parent < 0 && p >= 0 ? world_[size_t(p)] : mlod_mat4_identity();
			if (node.matrix.size() == 16)
				sheared += mlod_mat4_to_trs(&local_[size_t(k)], &j.rest, 1e-4f) != 0;
			else
				j.rest = node_trs(node);
		}
		if (m_.skins.empty() && count > 0)
			note("the document has no skins: its %d joints are the animated nodes and the nodes between them", count);
		if (sheared)
			warn("%d joint nodes have a matrix that is not a TRS (shear or singular); their rest pose is approximated",
			     sheared);
		for (size_t k = 0; k < n; k++) {
			int p = parent_[k];
			if (is_joint[k] || p < 0 || !is_joint[size_t(p)] || !m_.nodes[k].children.empty() || !is_end_site(int(k)))
				continue;
			mlod_joint &j = s.joints[joint_of_[size_t(p)]];
			if (j.has_end_site) {
				warn("joint %s has more than one End Site node; node %zu is ignored", quoted(j.name).c_str(), k);
				continue;
			}
			j.has_end_site = 1;
			j.end_site = node_trs(m_.nodes[k]).t;
		}
	}

	void skins()
	{
		mlod_skeleton &s = c_.skeleton;
		s.skins = c_array<mlod_skin>(m_.skins.size());
		s.skin_count = int(m_.skins.size());
		/* Each joint's root, once (the joints are parents first): walking
		 * each joint up to it took time quadratic in the depth. */
		std::vector<int> root(size_t(s.joint_count));
		for (int j = 0; j < s.joint_count; j++)
			root[size_t(j)] = s.joints[j].parent >= 0 ? root[size_t(s.joints[j].parent)] : j;
		std::vector<int> skin_of_root(size_t(s.joint_count), -1); /* the last skin that counted the root */
		for (size_t i = 0; i < m_.skins.size(); i++) {
			const tinygltf::Skin &src = m_.skins[i];
			mlod_skin &k = s.skins[i];
			size_t n = src.joints.size();
			k.name = c_string(src.name);
			k.gltf_index = int(i);
			k.joints = c_array<int>(n);
			k.inverse_bind = c_array<mlod_mat4>(n);
			k.joint_count = int(n);
			std::vector<float> ibm;
			if (src.inverseBindMatrices >= 0) {
				ibm = read_floats(m_, src.inverseBindMatrices, "skin " + std::to_string(i) + " inverseBindMatrices",
				                  TINYGLTF_TYPE_MAT4);
				if (ibm.size() < 16 * n)
					fail(MLOD_ERR_PARSE, "skin %zu: %zu inverse bind matrices for %zu joints", i, ibm.size() / 16, n);
			}
			size_t roots = 0;
			for (size_t j = 0; j < n; j++) {
				k.joints[j] = joint_of_[size_t(src.joints[j])];
				k.inverse_bind[j] = mlod_mat4_identity();
				if (!ibm.empty())
					memcpy(k.inverse_bind[j].m, &ibm[16 * j], sizeof(float[16]));
				int r = root[size_t(k.joints[j])];
				if (skin_of_root[size_t(r)] != int(i)) {
					skin_of_root[size_t(r)] = int(i);
					roots++;
				}
			}
			if (roots > 1)
				note("skin %zu \"%s\": its joints have no common root (%zu separate hierarchies)", i, k.name, roots);
		}
	}

	/* Index of set n in an attribute name like "TEXCOORD_3", or -1. */
	static int set_index(const std::string &name, const char *prefix)
	{
		size_t len = strlen(prefix);
		if (name.compare(0, len, prefix) != 0 || name.size() == len || name.size() > len + 3)
			return -1;
		for (size_t i = len; i < name.size(); i++)
			if (!isdigit((unsigned char)name[i]))
				return -1;
		return atoi(name.c_str() + len);
	}

	void primitive(size_t mi, size_t pi, mlod_primitive &out)
	{
		const tinygltf::Primitive &p = m_.meshes[mi].primitives[pi];
		std::string who = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
		auto find = [&](const std::map<std::string, int> &attrs, const std::string &name) {
			auto it = attrs.find(name);
			return it == attrs.end() ? -1 : it->second;
		};
		int position = find(p.attributes, "POSITION");
		if (position < 0)
			fail(MLOD_ERR_PARSE, "%s: no POSITION attribute", who.c_str());
		std::vector<float> pos = read_floats(m_, position, who + " POSITION", TINYGLTF_TYPE_VEC3);
		size_t n = pos.size() / 3;
		if (n > size_t(INT_MAX))
			fail(MLOD_ERR_NOMEM, "%s: too many vertices", who.c_str());
		out.vertex_count = int(n);
		out.positions = c_copy(pos);
		out.mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
		out.material = p.material;

		/* Reads an attribute with n elements as floats with comps
		 * components (an RGB color, other_type VEC3, gets alpha 1). */
		auto floats = [&](int accessor, const std::string &name, int type, int comps, int other_type = -1) {
			std::vector<float> v = read_floats(m_, accessor, who + " " + name, type, other_type);
			size_t have = size_t(layout_of(m_.accessors[size_t(accessor)]).components);
			if (v.size() / have != n)
				fail(MLOD_ERR_PARSE, "%s: %s has %zu elements, POSITION has %zu", who.c_str(), name.c_str(), v.size() / have, n);
			if (have < size_t(comps)) {
				std::vector<float> rgba(4 * n, 1.0f);
				for (size_t i = 0; i < n; i++)
					memcpy(&rgba[4 * i], &v[3 * i], 3 * sizeof(float));
				v.swap(rgba);
			}
			return c_copy(v);
		};
		int normal = find(p.attributes, "NORMAL"), tangent = find(p.attributes, "TANGENT");
		if (normal >= 0)
			out.normals = floats(normal, "NORMAL", TINYGLTF_TYPE_VEC3, 3);
		if (tangent >= 0)
			out.tangents = floats(tangent, "TANGENT", TINYGLTF_TYPE_VEC4, 4);
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			int a = find(p.attributes, "TEXCOORD_" + std::to_string(k));
			if (a < 0)
				break;
			out.uvs[k] = floats(a, "TEXCOORD_" + std::to_string(k), TINYGLTF_TYPE_VEC2, 2);
			out.uv_set_count = k + 1;
		}
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			int a = find(p.attributes, "COLOR_" + std::to_string(k));
			if (a < 0)
				break;
			out.colors[k] = floats(a, "COLOR_" + std::to_string(k), TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TYPE_VEC3);
			out.color_set_count = k + 1;
		}
		for (int k = 0; k < MLOD_MAX_SETS; k++) {
			std::string jn = "JOINTS_" + std::to_string(k), wn = "WEIGHTS_" + std::to_string(k);
			int ja = find(p.attributes, jn), wa = find(p.attributes, wn);
			if (ja < 0 || wa < 0)
				break;
			std::vector<uint32_t> joints = read_uints(m_, ja, who + " " + jn, TINYGLTF_TYPE_VEC4);
			if (joints.size() / 4 != n)
				fail(MLOD_ERR_PARSE, "%s: %s has %zu elements, POSITION has %zu", who.c_str(), jn.c_str(), joints.size() / 4, n);
			std::vector<uint16_t> narrow(joints.size());
			for (size_t i = 0; i < joints.size(); i++) {
				if (joints[i] > 0xFFFF)
					fail(MLOD_ERR_PARSE, "%s: %s of vertex %zu is %u, out of range", who.c_str(), jn.c_str(), i / 4, joints[i]);
				narrow[i] = uint16_t(joints[i]);
			}
			out.joints[k] = c_copy(narrow);
			out.weights[k] = floats(wa, wn, TINYGLTF_TYPE_VEC4, 4);
			out.weight_set_count = k + 1;
		}
		static const char *const prefixes[] = {"TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"};
		const int used[] = {out.uv_set_count, out.color_set_count, out.weight_set_count, out.weight_set_count};
		for (const auto &kv : p.attributes)
			for (int s = 0; s < 4; s++)
				if (set_index(kv.first, prefixes[s]) >= used[s])
					warn("%s: attribute %s is not decoded (sets are numbered from 0, JOINTS_n with WEIGHTS_n, "
					     "at most %d)", who.c_str(), quoted(kv.first).c_str(), MLOD_MAX_SETS);
		if (p.indices >= 0) {
			std::vector<uint32_t> idx = read_uints(m_, p.indices, who + " indices", TINYGLTF_TYPE_SCALAR);
			for (size_t i = 0; i < idx.size(); i++)
				if (idx[i] >= n)
					fail(MLOD_ERR_PARSE, "%s: index %zu is %u, out of range (%zu vertices)", who.c_str(), i, idx[i], n);
			if (idx.size() > size_t(INT_MAX))
				fail(MLOD_ERR_NOMEM, "%s: too many indices", who.c_str());
			out.indices = c_copy(idx);
			out.index_count = int(idx.size());
		}
		out.targets = c_array<mlod_morph_target>(p.targets.size());
		out.target_count = int(p.targets.size());
		for (size_t t = 0; t < p.targets.size(); t++) {
			std::string tn = "morph target " + std::to_string(t) + " ";
			int a;
			if ((a = find(p.targets[t], "POSITION")) >= 0)
				out.targets[t].positions = floats(a, tn + "POSITION", TINYGLTF_TYPE_VEC3, 3);
			if ((a = find(p.targets[t], "NORMAL")) >= 0)
				out.targets[t].normals = floats(a, tn + "NORMAL", TINYGLTF_TYPE_VEC3, 3);
			if ((a = find(p.targets[t], "TANGENT")) >= 0)
				out.targets[t].tangents = floats(a, tn + "TANGENT", TINYGLTF_TYPE_VEC3, 3);
		}
	}

	void meshes()
	{
		c_.meshes = c_array<mlod_mesh>(m_.meshes.size());
		c_.mesh_count = int(m_.meshes.size());
		for (size_t i = 0; i < m_.meshes.size(); i++) {
			mlod_mesh &mesh = c_.meshes[i];
			mesh.name = c_string(m_.meshes[i].name);
			mesh.gltf_index = int(i);
			mesh.primitives = c_array<mlod_primitive>(m_.meshes[i].primitives.size());
			mesh.primitive_count = int(m_.meshes[i].primitives.size());
			for (size_t p = 0; p < m_.meshes[i].primitives.size(); p++)
				primitive(i, p, mesh.primitives[p]);
		}
	}

	/* Skinned vertices must name joints of the skin (where they have weight). */
	void check_skinning(size_t node, const mlod_mesh &mesh, const mlod_skin &skin) const
	{
		for (int p = 0; p < mesh.primitive_count; p++) {
			const mlod_primitive &pr = mesh.primitives[p];
			for (int s = 0; s < pr.weight_set_count; s++)
				for (size_t i = 0; i < 4 * size_t(pr.vertex_count); i++)
					if (pr.weights[s][i] > 0 && pr.joints[s][i] >= skin.joint_count)
						fail(MLOD_ERR_PARSE, "node %zu: mesh %d primitive %d vertex %zu uses joint %u, but skin %d has %d joints",
						     node, mesh.gltf_index, p, i / 4, pr.joints[s][i], skin.gltf_index, skin.joint_count);
		}
	}

	/* One instance per node with a mesh that the default scene shows, in
	 * node order. Nodes outside it (MSFT_lod levels, say) are not drawn. */
	void instances()
	{
		std::vector<mlod_instance> list;
		int hidden = 0;
		for (size_t k = 0; k < m_.nodes.size(); k++) {
			const tinygltf::Node &node = m_.nodes[k];
			if (node.mesh < 0)
				continue;
			if (!shown_[k]) {
				hidden++;
				continue;
			}
			mlod_instance in;
			in.mesh = node.mesh;
			in.node = int(k);
			in.skin = node.skin;
			in.joint = -1;
			in.offset = mlod_mat4_identity();
			if (in.skin >= 0) {
				check_skinning(k, c_.meshes[in.mesh], c_.skeleton.skins[in.skin]);
			} else {
				/* Hang it under its nearest joint, or place it in the world. */
				mlod_mat4 offset = mlod_mat4_identity();
				int a = int(k);
				while (a >= 0 && joint_of_[size_t(a)] < 0) {
					offset = mlod_mat4_mul(&local_[size_t(a)], &offset);
					a = parent_[size_t(a)];
				}
				in.joint = a >= 0 ? joint_of_[size_t(a)] : -1;
				in.offset = offset;
			}
			list.push_back(in);
		}
		c_.instances = c_copy(list);
		c_.instance_count = int(list.size());
		if (hidden)
			note("%d nodes with a mesh are not in the default scene (MSFT_lod levels, say): they are not instances",
			     hidden);
	}

	/* Skin weights glTF does not allow, made valid by mlod's one rule
	 * (mlod_primitive_fix_weights): the primitives of each mesh a skinned
	 * node uses (an instance, or a node outside the scene: an MSFT_lod
	 * level), so that every level a tool writes from them is valid (the
	 * primitives changed go into fixed_, for set_skin_weights to write
	 * into the document's own accessors). An all-zero vertex goes on
	 * the skin's root, a skin joint index; a mesh whose skins have their
	 * roots at different indices keeps such vertices as they are, with a
	 * warning (mlod-pack then puts each on its own part's skin's root). */
	void weights()
	{
		for (int m = 0; m < c_.mesh_count; m++) {
			int skin = -1, root = -1;
			bool agree = true;
			auto use = [&](int s) {
				if (s < 0 || s >= c_.skeleton.skin_count)
					return;
				int r = mlod_skin_root(&c_.skeleton, s);
				if (skin < 0)
					skin = s, root = r;
				else if (r != root)
					agree = false;
			};
			for (int i = 0; i < c_.instance_count; i++)
				if (c_.instances[i].mesh == m)
					use(c_.instances[i].skin);
			for (size_t k = 0; k < m_.nodes.size(); k++)
				if (m_.nodes[k].mesh == m)
					use(m_.nodes[k].skin);
			if (skin < 0)
				continue;
			const mlod_skin &sk = c_.skeleton.skins[skin];
			std::string name = root >= 0 ? quoted(c_.skeleton.joints[sk.joints[root]].name) : "\"\"";
			for (int p = 0; p < c_.meshes[m].primitive_count; p++) {
				mlod_weight_fix fix;
				const bool rule = agree && root >= 0;
				mlod_primitive_fix_weights(&c_.meshes[m].primitives[p], rule ? root : -1, &fix);
				if (fixed_ && ((rule && fix.unweighted > 0) || fix.rescaled > 0 || fix.merged > 0))
					fixed_->emplace_back(m, p);
				if (!rule && fix.unweighted > 0)
					warn("mesh %d primitive %d: %d vertices have no weight (vertex %d the first), and the skins that "
					     "use the mesh have no common root joint: they stay without weight", m, p, fix.unweighted,
					     fix.first_unweighted);
				/* The pack's words for the same rule (mlod-pack(1)). */
				else if (fix.unweighted == 1)
					warn("mesh %d primitive %d: vertex %d has no weight: it follows the skin's root joint %s", m, p,
					     fix.first_unweighted, name.c_str());
				else if (fix.unweighted > 1)
					warn("mesh %d primitive %d: %d vertices have no weight (vertex %d the first): they follow the "
					     "skin's root joint %s", m, p, fix.unweighted, fix.first_unweighted, name.c_str());
				if (fix.merged == 1)
					warn("mesh %d primitive %d: vertex %d names one joint in two influences: merged into one", m, p,
					     fix.first_merged);
				else if (fix.merged > 1)
					warn("mesh %d primitive %d: %d vertices name one joint in two influences (vertex %d the first): "
					     "merged into one", m, p, fix.merged, fix.first_merged);
				if (fix.rescaled == 1)
					warn("mesh %d primitive %d: the weights of vertex %d sum to %.9g, not 1: scaled to 1", m, p,
					     fix.first_rescaled, double(fix.first_sum));
				else if (fix.rescaled > 1)
					warn("mesh %d primitive %d: the weights of %d vertices do not sum to 1 (vertex %d the first: %.9g): "
					     "scaled to 1", m, p, fix.rescaled, fix.first_rescaled, double(fix.first_sum));
			}
		}
	}

	/* A clip per animation with joint channels: one that animates morph
	 * weights or other nodes only (a mesh without joints) has no joint
	 * motion and stays in the document alone (a pack's DOC keeps its
	 * morph weights channels, mlod(5)). */
	void clips()
	{
		int not_joint = 0, weights = 0, outside = 0;
		auto joint_channel = [&](const tinygltf::AnimationChannel &ch) {
			return ch.target_path != "weights" && is_trs(ch.target_path) && ch.target_node >= 0 &&
			       joint_of_[size_t(ch.target_node)] >= 0;
		};
		std::vector<size_t> with_joints;
		for (size_t a = 0; a < m_.animations.size(); a++) {
			bool any = false;
			for (const tinygltf::AnimationChannel &ch : m_.animations[a].channels)
				any = any || joint_channel(ch);
			if (any || c_.skeleton.joint_count > 0)
				with_joints.push_back(a);
			else
				outside++;
		}
		c_.clips = c_array<mlod_clip>(with_joints.size());
		c_.clip_count = int(with_joints.size());
		for (size_t q = 0; q < with_joints.size(); q++) {
			size_t a = with_joints[q];
			const tinygltf::Animation &anim = m_.animations[a];
			mlod_clip &clip = c_.clips[q];
			clip.name = c_string(anim.name);
			clip.gltf_index = int(a);
			std::vector<const tinygltf::AnimationChannel *> kept;
			for (const tinygltf::AnimationChannel &ch : anim.channels) {
				if (ch.target_path == "weights")
					weights++;
				else if (!joint_channel(ch))
					not_joint++;
				else
					kept.push_back(&ch);
			}
			clip.channels = c_array<mlod_channel>(kept.size());
			clip.channel_count = int(kept.size());
			for (size_t i = 0; i < kept.size(); i++) {
				channel(a, *kept[i], clip.channels[i]);
				clip.duration = std::max(clip.duration, clip.channels[i].times[clip.channels[i].key_count - 1]);
			}
			bvh_frames(a, clip);
		}
		if (not_joint)
			note("%d animation channels target nodes that are not joints (kept in the document, not in the clips)",
			     not_joint);
		if (weights)
			note("%d animation channels animate morph target weights (kept in the document, outside the joint clips)",
			     weights);
		if (outside)
			note("%d animations without joints to animate (morph target weights, say) are kept in the document, "
			     "not as clips: no joint motion to reduce",
			     outside);
	}

	/* A BVH's clip keeps its frame time in extras.mlod_bvh.frame_time of
	 * its animation (mlod_load writes it), so that its frames survive the
	 * glb: the clip is sampled again (frame_time, frame_count) when every
	 * joint channel is linear with the same key times, one key per frame
	 * (within half a frame of k times the frame time). Else the mark is
	 * stale (the animation was edited) and the clip is read as keys. */
	void bvh_frames(size_t a, mlod_clip &clip) const
	{
		const json e = current_extras(doc_, "/animations/" + std::to_string(a) + "/extras",
		                              m_.animations[a].extras);
		if (!e.is_object() || !e.contains(bvh_key) || !e[bvh_key].is_object() || clip.channel_count == 0)
			return;
		const json &ft = e[bvh_key].contains(bvh_frame_time) ? e[bvh_key][bvh_frame_time] : json();
		if (!ft.is_number())
			return;
		const float f = float(ft.get<double>());
		const mlod_channel &first = clip.channels[0];
		const int n = first.key_count;
		if (!(f > 0.0f) || !std::isfinite(f) || n < 1)
			return;
		for (int i = 0; i < clip.channel_count; i++) {
			const mlod_channel &ch = clip.channels[i];
			if (ch.interp != MLOD_INTERP_LINEAR || ch.key_count != n ||
			    std::memcmp(ch.times, first.times, sizeof(float) * size_t(n)) != 0)
				return;
		}
		for (int k = 0; k < n; k++)
			if (!(std::fabs(double(first.times[k]) - double(k) * f) <= 0.5 * f))
				return;
		clip.frame_time = f;
		clip.frame_count = n;
	}

	void channel(size_t a, const tinygltf::AnimationChannel &src, mlod_channel &ch)
	{
		const tinygltf::AnimationSampler &s = m_.animations[a].samplers[size_t(src.sampler)];
		std::string who = "animation " + std::to_string(a) + " sampler " + std::to_string(src.sampler);
		ch.joint = joint_of_[size_t(src.target_node)];
		ch.path = src.target_path == "translation" ? MLOD_PATH_TRANSLATION
		          : src.target_path == "rotation"  ? MLOD_PATH_ROTATION
		                                           : MLOD_PATH_SCALE;
		if (s.interpolation.empty() || s.interpolation == "LINEAR")
			ch.interp = MLOD_INTERP_LINEAR;
		else if (s.interpolation == "STEP")
			ch.interp = MLOD_INTERP_STEP;
		else if (s.interpolation == "CUBICSPLINE")
			ch.interp = MLOD_INTERP_CUBICSPLINE;
		else
			fail(MLOD_ERR_PARSE, "%s: unknown interpolation \"%s\"", who.c_str(), s.interpolation.c_str());
		std::vector<float> times = read_floats(m_, s.input, who + " input", TINYGLTF_TYPE_SCALAR);
		if (times.empty())
			fail(MLOD_ERR_PARSE, "%s: no keys", who.c_str());
		if (times.size() > size_t(INT_MAX))
			fail(MLOD_ERR_NOMEM, "%s: too many keys", who.c_str());
		for (size_t k = 1; k < times.size(); k++)
			if (!(times[k] > times[k - 1]))
				fail(MLOD_ERR_PARSE, "%s: key times do not increase (key %zu at %g s follows %g s)", who.c_str(), k,
				     double(times[k]), double(times[k - 1]));
		int comps = ch.path == MLOD_PATH_ROTATION ? 4 : 3;
		std::vector<float> values =
		    read_floats(m_, s.output, who + " output", ch.path == MLOD_PATH_ROTATION ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3);
		size_t per_key = size_t(comps) * (ch.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		if (values.size() != per_key * times.size())
			fail(MLOD_ERR_PARSE, "%s: output has %zu elements for %zu keys, not %zu (%s)", who.c_str(),
			     values.size() / size_t(comps), times.size(), per_key / size_t(comps) * times.size(),
			     ch.interp == MLOD_INTERP_CUBICSPLINE ? "in-tangent, value and out-tangent per key" : "one per key");
		ch.times = c_copy(times);
		ch.values = c_copy(values);
		ch.key_count = int(times.size());
	}

	static std::string lines(const std::vector<std::string> &v)
	{
		std::string all;
		for (const std::string &n : v)
			all += (all.empty() ? "" : "\n") + n;
		return all;
	}

	void notes()
	{
		std::string outside;
		int count = 0, moving = 0;
		for (size_t k = 0; k < m_.nodes.size() && !m_.skins.empty(); k++) {
			if (joint_of_[k] < 0 || in_skin_[k])
				continue;
			if (count++ < 8)
				outside += std::string(count > 1 ? ", " : "") + "\"" + m_.nodes[k].name + "\"";
			moving += animated_[k];
		}
		if (count)
			note("%d joint nodes are in no skin (they connect skin joints: %s%s), %d of them animated", count,
			     outside.c_str(), count > 8 ? ", ..." : "", moving);
		if (notes_.empty())
			return;
		c_.notes = c_string(lines(notes_));
		if (!warnings_.empty())
			c_.warnings = c_string(lines(warnings_));
	}
};

} /* namespace */

/* Fills c from doc (may throw); fixed (may be null) gets the (mesh,
 * primitive) pairs whose skin weights mlod's rule changed. */
void read_character(const mlod_gltf &doc, mlod_character &c, std::vector<std::pair<int, int>> *fixed)
{
	CharacterReader(doc, c, fixed).read();
}

/* ------------------------------------------------------------------ */
/* Character -> glTF                                                   */
/* ------------------------------------------------------------------ */

/* Appends bytes to buffer 0 (made if there is none) at a 4-byte aligned
 * offset, as a new buffer view; returns the view. */
static int append_view(Model &m, const void *data, size_t size, int target)
{
	if (m.buffers.empty())
		m.buffers.emplace_back();
	std::vector<unsigned char> &b = m.buffers[0].data;
	b.resize((b.size() + 3) / 4 * 4, 0);
	tinygltf::BufferView v;
	v.buffer = 0;
	v.byteOffset = b.size();
	v.byteLength = size;
	v.target = target;
	const unsigned char *p = static_cast<const unsigned char *>(data);
	b.insert(b.end(), p, p + size);
	m.bufferViews.push_back(v);
	return int(m.bufferViews.size() - 1);
}

/* Appends an accessor over count elements of comps components at data.
 * With min_max, records the per-component bounds (floats only). */
int append_accessor(Model &m, const void *data, size_t count, int component_type, int type, int comps, int target,
                    bool min_max)
{
	size_t bytes = count * size_t(comps) * component_size(component_type);
	tinygltf::Accessor a;
	a.bufferView = append_view(m, data, bytes, target);
	a.byteOffset = 0;
	a.componentType = component_type;
	a.count = count;
	a.type = type;
	a.normalized = false;
	if (min_max) {
		const float *v = static_cast<const float *>(data);
		a.minValues.assign(size_t(comps), INFINITY);
		a.maxValues.assign(size_t(comps), -INFINITY);
		for (size_t i = 0; i < count; i++)
			for (size_t c = 0; c < size_t(comps); c++) {
				a.minValues[c] = std::min(a.minValues[c], double(v[i * size_t(comps) + c]));
				a.maxValues[c] = std::max(a.maxValues[c], double(v[i * size_t(comps) + c]));
			}
	}
	m.accessors.push_back(a);
	return int(m.accessors.size() - 1);
}

/* append_accessor for floats: comps 1 to 4 are SCALAR to VEC4, 16 is MAT4. */
int append_floats(Model &m, const float *v, size_t count, int comps, int target, bool min_max)
{
	static const int types[] = {0, TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
	int type = comps == 16 ? TINYGLTF_TYPE_MAT4 : types[comps];
	return append_accessor(m, v, count, TINYGLTF_COMPONENT_TYPE_FLOAT, type, comps, target, min_max);
}

/* Callers' data must be finite: JSON cannot hold NaN in min/max. */
void check_finite(const float *v, size_t n, const char *what)
{
	for (size_t i = 0; i < n; i++)
		if (!std::isfinite(v[i]))
			fail(MLOD_ERR_INVALID_ARG, "%s: value %zu is not finite", what, i);
}

/* Adds JOINTS_n (unsigned short) and WEIGHTS_n (float) of p to attributes. */
static void add_skinning(Model &m, const mlod_primitive &p, std::map<std::string, int> &attributes)
{
	size_t n = size_t(p.vertex_count);
	for (int k = 0; k < p.weight_set_count && k < MLOD_MAX_SETS; k++) {
		if (!p.joints[k] || !p.weights[k])
			continue;
		check_finite(p.weights[k], 4 * n, "weights");
		attributes["JOINTS_" + std::to_string(k)] = append_accessor(
		    m, p.joints[k], n, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
		attributes["WEIGHTS_" + std::to_string(k)] = append_floats(m, p.weights[k], n, 4, TINYGLTF_TARGET_ARRAY_BUFFER);
	}
}

/* A glTF primitive with new accessors for every attribute of p (POSITION
 * with min and max, 16-bit indices when the vertices allow). */
static tinygltf::Primitive make_primitive(Model &m, const mlod_primitive &p, int mesh_index, int index)
{
	char who[64];
	snprintf(who, sizeof who, "mesh %d primitive %d", mesh_index, index);
	if (p.vertex_count <= 0 || !p.positions)
		fail(MLOD_ERR_INVALID_ARG, "%s: no vertices", who);
	if (p.material < -1 || p.material >= int(m.materials.size()))
		fail(MLOD_ERR_INVALID_ARG, "%s: material %d does not exist in the document", who, p.material);
	size_t n = size_t(p.vertex_count);
	check_finite(p.positions, 3 * n, who);
	tinygltf::Primitive out;
	out.mode = p.mode;
	out.material = p.material;
	auto attribute = [&](const char *name, int k, const float *v, int comps, bool min_max = false) {
		if (v)
			out.attributes[k < 0 ? name : name + std::to_string(k)] =
			    append_floats(m, v, n, comps, TINYGLTF_TARGET_ARRAY_BUFFER, min_max);
	};
	attribute("POSITION", -1, p.positions, 3, true);
	attribute("NORMAL", -1, p.normals, 3);
	attribute("TANGENT", -1, p.tangents, 4);
	for (int k = 0; k < p.uv_set_count && k < MLOD_MAX_SETS; k++)
		attribute("TEXCOORD_", k, p.uvs[k], 2);
	for (int k = 0; k < p.color_set_count && k < MLOD_MAX_SETS; k++)
		attribute("COLOR_", k, p.colors[k], 4);
	add_skinning(m, p, out.attributes);
	if (p.index_count > 0 && p.indices) {
		size_t count = size_t(p.index_count);
		for (size_t i = 0; i < count; i++)
			if (p.indices[i] >= n)
				fail(MLOD_ERR_INVALID_ARG, "%s: index %zu is %u, out of range (%zu vertices)", who, i, p.indices[i], n);
		if (n <= 0xFFFF) { /* 65535 is the primitive restart value */
			std::vector<uint16_t> narrow(p.indices, p.indices + count);
			out.indices = append_accessor(m, narrow.data(), count, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
			                              TINYGLTF_TYPE_SCALAR, 1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
		} else {
			out.indices = append_accessor(m, p.indices, count, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
			                              1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
		}
	}
	for (int t = 0; t < p.target_count && p.targets; t++) {
		std::map<std::string, int> target;
		const mlod_morph_target &mt = p.targets[t];
		const float *parts[] = {mt.positions, mt.normals, mt.tangents};
		const char *names[] = {"POSITION", "NORMAL", "TANGENT"};
		for (int k = 0; k < 3; k++)
			if (parts[k])
				target[names[k]] = append_floats(m, parts[k], n, 3, TINYGLTF_TARGET_ARRAY_BUFFER, k == 0);
		out.targets.push_back(target);
	}
	return out;
}

/* Appends a mesh with mesh's primitives; returns its index. */
int add_mesh(Model &m, const mlod_mesh &mesh)
{
	if (mesh.primitive_count <= 0 || !mesh.primitives)
		fail(MLOD_ERR_INVALID_ARG, "mesh \"%s\": no primitives", mesh.name ? mesh.name : "");
	tinygltf::Mesh out;
	out.name = utf8(mesh.name);
	int index = int(m.meshes.size());
	for (int p = 0; p < mesh.primitive_count; p++)
		out.primitives.push_back(make_primitive(m, mesh.primitives[p], index, p));
	m.meshes.push_back(std::move(out));
	return index;
}

/* Appends a copy of mesh `mesh` with JOINTS_n/WEIGHTS_n from m; the rest
 * shares the original accessors, and extras are copied exactly. */
int add_mesh_reskinned(mlod_gltf &doc, int mesh, const mlod_mesh &m)
{
	Model &model = doc.model;
	if (mesh < 0 || size_t(mesh) >= model.meshes.size())
		fail(MLOD_ERR_INVALID_ARG, "mesh %d does not exist", mesh);
	tinygltf::Mesh copy = model.meshes[size_t(mesh)];
	if (m.primitive_count != int(copy.primitives.size()) || !m.primitives)
		fail(MLOD_ERR_INVALID_ARG, "mesh %d has %zu primitives, the new skinning %d", mesh, copy.primitives.size(),
		     m.primitive_count);
	for (size_t p = 0; p < copy.primitives.size(); p++) {
		std::map<std::string, int> &attributes = copy.primitives[p].attributes;
		auto position = attributes.find("POSITION");
		const mlod_primitive &mp = m.primitives[p];
		if (position == attributes.end() || model.accessors[size_t(position->second)].count != size_t(mp.vertex_count))
			fail(MLOD_ERR_INVALID_ARG, "mesh %d primitive %zu: the new skinning has %d vertices, not as many as POSITION",
			     mesh, p, mp.vertex_count);
		for (auto it = attributes.begin(); it != attributes.end();)
			it = it->first.compare(0, 7, "JOINTS_") == 0 || it->first.compare(0, 8, "WEIGHTS_") == 0 ? attributes.erase(it)
			                                                                                       : std::next(it);
		add_skinning(model, mp, attributes);
	}
	int index = int(model.meshes.size());
	model.meshes.push_back(std::move(copy));
	std::string from = "/meshes/" + std::to_string(mesh) + "/", to = "/meshes/" + std::to_string(index) + "/";
	std::map<std::string, json> copied;
	for (auto it = doc.extras.lower_bound(from); it != doc.extras.end() && it->first.compare(0, from.size(), from) == 0; ++it)
		copied[to + it->first.substr(from.size())] = it->second;
	doc.extras.insert(copied.begin(), copied.end());
	return index;
}

/* Appends a skin whose joint k is node nodes[skin.joints[k]]. */
int add_skin(Model &m, const mlod_skin &skin, const std::vector<int> &nodes)
{
	if (skin.joint_count <= 0 || !skin.joints)
		fail(MLOD_ERR_INVALID_ARG, "skin \"%s\": no joints", skin.name ? skin.name : "");
	tinygltf::Skin out;
	out.name = utf8(skin.name);
	for (int k = 0; k < skin.joint_count; k++) {
		int j = skin.joints[k];
		if (j < 0 || size_t(j) >= nodes.size() || nodes[size_t(j)] < 0 || size_t(nodes[size_t(j)]) >= m.nodes.size())
			fail(MLOD_ERR_INVALID_ARG, "skin \"%s\": joint %d (%d) has no node in the document", out.name.c_str(), k, j);
		out.joints.push_back(nodes[size_t(j)]);
	}
	std::vector<float> ibm(16 * size_t(skin.joint_count));
	for (int k = 0; k < skin.joint_count; k++) {
		mlod_mat4 id = mlod_mat4_identity();
		memcpy(&ibm[16 * size_t(k)], skin.inverse_bind ? skin.inverse_bind[k].m : id.m, sizeof(float[16]));
	}
	check_finite(ibm.data(), ibm.size(), "inverse bind matrices");
	out.inverseBindMatrices = append_floats(m, ibm.data(), size_t(skin.joint_count), 16, 0);
	m.skins.push_back(std::move(out));
	return int(m.skins.size() - 1);
}

/* Appends an animation whose channels target nodes[channel.joint]; key
 * times shared by several channels are stored once. */
int add_animation(Model &m, const mlod_clip &clip, const std::vector<int> &nodes)
{
	if (clip.channel_count <= 0 || !clip.channels)
		fail(MLOD_ERR_INVALID_ARG, "clip \"%s\": no channels (a glTF animation needs one)", clip.name ? clip.name : "");
	tinygltf::Animation out;
	out.name = utf8(clip.name);
	std::map<std::vector<float>, int> inputs;
	static const char *const paths[] = {"translation", "rotation", "scale"};
	static const char *const interps[] = {"LINEAR", "STEP", "CUBICSPLINE"};
	for (int i = 0; i < clip.channel_count; i++) {
		const mlod_channel &ch = clip.channels[i];
		if (ch.joint < 0 || size_t(ch.joint) >= nodes.size() || nodes[size_t(ch.joint)] < 0 ||
		    size_t(nodes[size_t(ch.joint)]) >= m.nodes.size())
			fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: joint %d has no node in the document", out.name.c_str(), i, ch.joint);
		if (ch.key_count <= 0 || !ch.times || !ch.values || unsigned(ch.path) > MLOD_PATH_SCALE ||
		    unsigned(ch.interp) > MLOD_INTERP_CUBICSPLINE)
			fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: no keys, or a bad path or interpolation", out.name.c_str(), i);
		size_t keys = size_t(ch.key_count), comps = ch.path == MLOD_PATH_ROTATION ? 4 : 3;
		size_t per_key = comps * (ch.interp == MLOD_INTERP_CUBICSPLINE ? 3 : 1);
		std::vector<float> times(ch.times, ch.times + keys), values(ch.values, ch.values + keys * per_key);
		check_finite(times.data(), keys, "key times");
		check_finite(values.data(), values.size(), "key values");
		for (size_t k = 1; k < keys; k++)
			if (!(times[k] > times[k - 1]))
				fail(MLOD_ERR_INVALID_ARG, "clip \"%s\" channel %d: key times do not increase", out.name.c_str(), i);
		/* Unit quaternions; cubic tangents stay as they are. A key unit to
		 * single precision (its squared length within 1e-6 of 1, as
		 * mlod_quat_normalize's are) is written as given: normalising it
		 * again moves some keys by a last bit, and not to a fixed point
		 * (31 of the walk's 16,244 keys cycle), so the keys read back
		 * would depend on how many times they were written (a BVH read
		 * directly against the glb a stage makes of it:
		 * cli/pack_bvh_stages; the BVH reader normalises once more). */
		if (ch.path == MLOD_PATH_ROTATION) {
			size_t first = ch.interp == MLOD_INTERP_CUBICSPLINE ? 4 : 0;
			for (size_t k = 0; k < keys; k++) {
				float *q = &values[k * per_key + first];
				double n2 = double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3];
				if (std::fabs(n2 - 1.0) <= 1e-6)
					continue;
				mlod_quat n = mlod_quat_normalize(mlod_quat{q[0], q[1], q[2], q[3]});
				q[0] = n.x, q[1] = n.y, q[2] = n.z, q[3] = n.w;
			}
		}
		/* Rotations on the lattice of normalised shorts are written as such
		 * (as given: the lattice is as unit as it gets). */
		std::vector<int16_t> shorts;
		if (ch.short_values && ch.path == MLOD_PATH_ROTATION && ch.interp != MLOD_INTERP_CUBICSPLINE)
			for (size_t k = 0; k < keys * per_key; k++) {
				long n = lrint(double(ch.values[k]) * 32767.0);
				if (n < -32767 || n > 32767 || float(n / 32767.0) != ch.values[k]) {
					shorts.clear();
					break;
				}
				shorts.push_back(int16_t(n));
			}
		auto in = inputs.find(times);
		if (in == inputs.end())
			in = inputs.emplace(times, append_floats(m, times.data(), keys, 1, 0, true)).first;
		tinygltf::AnimationSampler s;
		s.input = in->second;
		if (!shorts.empty()) {
			s.output = append_accessor(m, shorts.data(), keys, TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_TYPE_VEC4, 4, 0,
			                           false);
			m.accessors.back().normalized = true;
		} else {
			s.output = append_floats(m, values.data(), values.size() / comps, int(comps), 0);
		}
		s.interpolation = interps[ch.interp];
		out.samplers.push_back(s);
		tinygltf::AnimationChannel c;
		c.sampler = int(out.samplers.size() - 1);
		c.target_node = nodes[size_t(ch.joint)];
		c.target_path = paths[ch.path];
		out.channels.push_back(c);
	}
	m.animations.push_back(std::move(out));
	return int(m.animations.size() - 1);
}

/* The scene parentless nodes join: the default one, made if needed. */
tinygltf::Scene &default_scene(Model &m)
{
	if (m.scenes.empty())
		m.scenes.emplace_back();
	if (m.defaultScene < 0)
		m.defaultScene = 0;
	return m.scenes[size_t(m.defaultScene)];
}

/* Fills an empty model from a character: joint nodes first (node i is
 * joint i), a node above each root whose base is not the identity, End
 * Site nodes, meshes, skins, instance nodes (rigid ones under their joint)
 * and one animation per clip with channels. */
void build_document(Model &m, const mlod_character &c)
{
	m.asset.version = "2.0";
	m.asset.generator = "mlod";
	const mlod_skeleton &s = c.skeleton;
	std::vector<int> roots, node_of_joint; /* joint i is node i */
	m.nodes.resize(size_t(s.joint_count));
	for (int i = 0; i < s.joint_count; i++) {
		const mlod_joint &j = s.joints[i];
		node_of_joint.push_back(i);
		m.nodes[size_t(i)].name = utf8(j.name);
		set_trs(m.nodes[size_t(i)], j.rest);
		if (j.channel_count > 0) {
			static const char *const names[6] = {"Xposition", "Yposition", "Zposition",
			                                     "Xrotation", "Yrotation", "Zrotation"};
			Value::Array channels;
			for (int k = 0; k < j.channel_count && k < 6; k++)
				if (j.channels[k] < 6)
					channels.push_back(Value(std::string(names[j.channels[k]])));
			m.nodes[size_t(i)].extras =
				Value(Value::Object{{bvh_key, Value(Value::Object{{bvh_channels, Value(channels)}})}});
		}
	}
	for (int i = 0; i < s.joint_count; i++) {
		const mlod_joint &j = s.joints[i];
		if (j.parent >= 0) {
			m.nodes[size_t(j.parent)].children.push_back(i);
		} else if (is_identity(j.base)) {
			roots.push_back(i);
		} else { /* the world transform above a root: a node of its own */
			tinygltf::Node base;
			base.name = utf8(j.name) + "_base";
			set_transform(base, j.base);
			base.children.push_back(i);
			m.nodes.push_back(base);
			roots.push_back(int(m.nodes.size() - 1));
		}
		if (j.has_end_site) {
			tinygltf::Node end;
			end.name = utf8(j.name) + "_end";
			set_trs(end, mlod_trs{j.end_site, mlod_quat_identity(), mlod_v3{1, 1, 1}});
			end.extras = Value(Value::Object{{record_key, Value(Value::Object{{record_end_site, Value(true)}})}});
			m.nodes.push_back(end);
			m.nodes[size_t(i)].children.push_back(int(m.nodes.size() - 1));
		}
	}
	for (int i = 0; i < c.mesh_count; i++) {
		mlod_mesh mesh = c.meshes[i];
		/* A new document has no materials. */
		std::vector<mlod_primitive> prims(mesh.primitives, mesh.primitives + mesh.primitive_count);
		for (mlod_primitive &p : prims)
			p.material = -1;
		mesh.primitives = prims.data();
		add_mesh(m, mesh);
	}
	for (int i = 0; i < s.skin_count; i++)
		add_skin(m, s.skins[i], node_of_joint);
	for (int i = 0; i < c.instance_count; i++) {
		const mlod_instance &in = c.instances[i];
		tinygltf::Node node;
		node.name = utf8(c.meshes[in.mesh].name);
		node.mesh = in.mesh;
		node.skin = in.skin;
		if (in.skin < 0)
			set_transform(node, in.offset);
		m.nodes.push_back(node);
		int k = int(m.nodes.size() - 1);
		if (in.skin < 0 && in.joint >= 0)
			m.nodes[size_t(in.joint)].children.push_back(k);
		else
			roots.push_back(k);
	}
	for (int i = 0; i < c.clip_count; i++)
		if (c.clips[i].channel_count > 0)
			add_animation(m, c.clips[i], node_of_joint);
	default_scene(m).nodes = roots;
}

} /* namespace mlod_gltf_internal */
