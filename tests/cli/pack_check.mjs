// pack_check.mjs: checks the container of a .mlod pack as mlod(5) and
// lib/rt/mlod_pack.h lay it out (header, TOC, CRCs, alignment, order,
// stream containers, INFO), independently of the C reader, and prints a
// summary as JSON for the tests to check. Exits 1 naming the first problem.
//
//   node tests/cli/pack_check.mjs FILE.mlod [--doc OUT.glb]
//
// --doc writes the DOC chunk's glb to OUT.glb.
// It decodes no meshopt-coded stream: the round trip through the reader
// (lib/rt/rd_*.c) is for the tests that come with it. A skeleton level's
// palette (format 7.0: 'KEPT', 'PALR', 'PALX'; no 'PALJ', no 'PALB') is
// checked for its streams and counts, and where 'PALR' is raw or in byte
// planes (stream codecs 4 and 5, which this script decodes) every
// reference (0 the own 'IBMS' entry, 1..P 'IBMS' entry v - 1, above P a
// 'PALX' matrix); "palette" in the summary counts each level's three
// kinds (null where 'PALR' is meshopt-coded), and where 'KEPT' is, its
// joints are checked (increasing, below the joint count). "planes" counts
// the streams in byte planes, "sums" those of codec 6 (each decoded). A chunk with the
// zstd entropy stage (format 5.0) is undone with the zstd tool first; one
// with the prefix stage (format 6.0) with the chunks it needs as the tool's
// --patch-from reference: a MESH level's coarser MESH levels' containers,
// a skeleton level's SKELETON container.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { crc32 } from 'node:zlib';

const file = process.argv[2];
const b = readFileSync(file);
const die = (m) => { console.error(`pack_check: ${file}: ${m}`); process.exit(1); };
const fourcc = (u) => String.fromCharCode(u & 255, (u >> 8) & 255, (u >> 16) & 255, u >>> 24);

if (b.length < 32 || b.subarray(0, 4).toString('latin1') !== 'MLOD') die('no MLOD magic');
const major = b.readUInt16LE(4), minor = b.readUInt16LE(6), flags = b.readUInt32LE(8), n = b.readUInt32LE(12);
const size = Number(b.readBigUInt64LE(16));
if (major !== 9 || minor !== 0) die(`version ${major}.${minor}`);
if (flags !== 0) die('flags');
if (size !== b.length) die(`file_size ${size}, file ${b.length}`);
if (crc32(b.subarray(0, 28)) !== b.readUInt32LE(28)) die('header CRC');
if (32 + 48 * n > b.length) die('TOC past the end');
if (crc32(b.subarray(32, 32 + 48 * n)) !== b.readUInt32LE(24)) die('TOC CRC');

const chunks = [];
let end = 32 + 48 * n;
const meshes = []; // the MESH levels' containers so far: the prefix of a finer one (entropy 2)
let skeleton = null; // SKELETON's container: a skeleton level's prefix
for (let i = 0; i < n; i++) {
	const e = b.subarray(32 + 48 * i, 80 + 48 * i);
	const c = {
		type: fourcc(e.readUInt32LE(0)), layer: e[4], codec: e[5] & 15, entropy: e[5] >> 4, coded: e.readUInt32LE(12),
		level: e.readUInt16LE(6), item: e.readUInt16LE(8),
		offset: Number(e.readBigUInt64LE(16)), stored: e.readUInt32LE(24), raw: e.readUInt32LE(28),
		crc: e.readUInt32LE(32), error: e.readFloatLE(36), distance: e.readFloatLE(40), flags: e.readUInt16LE(10),
	};
	// flags: only ANIM's 1, nested on the clip's next coarser level (checked below)
	if ((c.flags && (c.type !== 'ANIM' || c.flags !== 1)) || (c.coded && !c.entropy) || e.readUInt32LE(44)) die(`chunk ${i}: reserved bytes`);
	// the entropy stage: zstd (1), or zstd on the chunks it needs (2: a MESH level but the coarsest, a skeleton level), never on INFO, its container at most the raw size
	const skel = c.type === 'SKEL' && c.level > 0;
	if (c.entropy > 2 || (c.entropy === 2 && !((c.type === 'MESH' && meshes.length) || (skel && skeleton))) || (c.entropy && (c.type === 'INFO' || c.coded < 4 || c.coded > c.raw))) die(`chunk ${i}: entropy ${c.entropy}, coded size ${c.coded}`);
	if (c.offset % 16) die(`chunk ${i}: offset ${c.offset} not 16-aligned`);
	if (c.offset < end) die(`chunk ${i}: overlaps`);
	if (b.subarray(end, c.offset).some((x) => x !== 0)) die(`chunk ${i}: padding not zero`);
	if (c.offset + c.stored > b.length) die(`chunk ${i}: past the end`);
	end = c.offset + c.stored;
	const stored = b.subarray(c.offset, end);
	if (crc32(stored) !== c.crc) die(`chunk ${i} (${c.type}): CRC`);
	let d = stored;
	if (c.entropy === 1) d = execFileSync('zstd', ['-d', '-q', '-c'], { input: stored, maxBuffer: 1 << 30 });
	if (c.entropy === 2) {
		const dir = mkdtempSync(join(tmpdir(), 'pack_check.'));
		writeFileSync(join(dir, 'prefix'), skel ? skeleton : Buffer.concat(meshes));
		try {
			d = execFileSync('zstd', ['-d', '-q', '-c', `--patch-from=${join(dir, 'prefix')}`], { input: stored, maxBuffer: 1 << 30 });
		} finally {
			rmSync(dir, { recursive: true });
		}
	}
	if (c.type === 'MESH') meshes.push(d);
	if (c.type === 'SKEL' && c.level === 0) skeleton = d;
	if (c.entropy && d.length !== c.coded) die(`chunk ${i} (${c.type}): zstd gave ${d.length} bytes, coded size ${c.coded}`);
	c.data = d;
	// ANIM level 0 states its error against the input clip (0 when lossless); its distance is 0
	if (c.level === 0 && ((c.error !== 0 && c.type !== 'ANIM') || c.distance !== 0)) die(`chunk ${i}: error or distance at level 0`);
	if (!(c.error >= 0) || (c.level > 0 && (c.error > 0) !== (c.distance > 0))) die(`chunk ${i}: error ${c.error}, distance ${c.distance}`);
	// distance = error * lines / (2 tan(fov / 2) pixels)
	const want = c.error * 1080 / (2 * Math.tan(Math.PI / 6));
	if (c.level > 0 && Math.abs(c.distance - want) > 1e-5 * want) die(`chunk ${i}: distance ${c.distance} for error ${c.error}`);
	// The stream container.
	const sc = d.readUInt32LE(0);
	let p = 4 + 16 * sc, raw = 4 + 16 * sc;
	c.streams = [];
	for (let s = 0; s < sc; s++) {
		const h = d.subarray(4 + 16 * s, 20 + 16 * s);
		const st = { tag: fourcc(h.readUInt32LE(0)), count: h.readUInt32LE(4), size: h.readUInt16LE(8), codec: h[10], stored: h.readUInt32LE(12) };
		if (h[11]) die(`chunk ${i}: stream ${s}: reserved`);
		if (st.size < 1 || st.size > 256) die(`chunk ${i}: stream ${st.tag}: element size ${st.size}`);
		if ((st.codec === 0 || st.codec === 4 || st.codec === 5) && st.stored !== st.count * st.size) die(`chunk ${i}: raw or plane stream ${st.tag}: stored ${st.stored}`);
		if (st.codec && c.codec === 0) die(`chunk ${i}: stream ${st.tag} of codec ${st.codec} in a chunk of codec none`);
		if (st.codec === 1 && st.size % 4) die(`chunk ${i}: vertex codec on element size ${st.size}`);
		if (st.codec === 2 && (st.size !== 2 && st.size !== 4 || st.count % 3)) die(`chunk ${i}: index codec on ${st.tag}`);
		if (st.codec === 3 && (st.size !== 2 && st.size !== 4 || st.tag !== 'IMAP')) die(`chunk ${i}: index sequence codec on ${st.tag}`);
		if (st.codec === 6 && (st.size !== 4 || st.stored !== 3 * st.count)) die(`chunk ${i}: sum codec on ${st.tag}: element size ${st.size}, stored ${st.stored}`);
		if (st.codec > 6) die(`chunk ${i}: stream codec ${st.codec}`);
		st.at = p;
		p += (st.stored + 3) & ~3;
		raw += (st.count * st.size + 3) & ~3;
		c.streams.push(st);
	}
	if (p !== d.length) die(`chunk ${i} (${c.type}): streams end at ${p}, chunk at ${d.length}`);
	if (raw !== c.raw) die(`chunk ${i} (${c.type}): raw size ${c.raw}, streams say ${raw}`);
	chunks.push(c);
}
if (end !== b.length) die('bytes after the last chunk');

// A stream's decoded bytes where no meshopt decoder is needed: raw (0),
// byte planes (4: byte j of element k at j * count + k; 5: the same of
// each byte minus the element before's, modulo 256; format 7.0), or sums
// (6: elements of 4 bytes summing to 255 as their first three; 7.0);
// else null.
const plain = (c, st) => {
	const s = c.data.subarray(st.at, st.at + st.stored), n = st.count, e = st.size;
	if (st.codec === 0) return s;
	if (st.codec === 6) { // each element's first three bytes; the fourth 255 minus their sum
		const out = Buffer.alloc(n * 4);
		for (let k = 0; k < n; k++) {
			const sum = s[3 * k] + s[3 * k + 1] + s[3 * k + 2];
			if (sum > 255) die(`stream ${st.tag}: element ${k}: its bytes sum to ${sum}`);
			out.set(s.subarray(3 * k, 3 * k + 3), 4 * k);
			out[4 * k + 3] = 255 - sum;
		}
		return out;
	}
	if (st.codec !== 4 && st.codec !== 5) return null;
	const out = Buffer.alloc(n * e);
	for (let j = 0; j < e; j++) {
		let acc = 0;
		for (let k = 0; k < n; k++) {
			acc = st.codec === 5 ? (acc + s[j * n + k]) & 255 : s[j * n + k];
			out[k * e + j] = acc;
		}
	}
	return out;
};

// Skeleton levels (format 7.0): the palette as references to SKELETON's
// 'IBMS' (P entries: its 'SKJT' count) or to the level's 'PALX'.
const palette = [];
if (n > 1 && chunks[1].type === 'SKEL') {
	const sk = chunks[1].streams, P = sk.length === 5 && sk[3].tag === 'SKJT' && sk[4].tag === 'IBMS' ? sk[3].count : -1;
	if (P < 0 || sk[4].count !== P || sk[4].size !== 64) die('SKEL streams');
	for (const c of chunks) {
		if (c.type !== 'SKEL' || c.level === 0) continue;
		const [k, r, x] = c.streams, tags = c.streams.map((t) => t.tag).join(',');
		if (tags !== 'KEPT,PALR,PALX' || k.size !== 4 || r.size !== 4 || x.size !== 64) die(`SKEL level ${c.level}: streams ${tags}`);
		if (r.count !== P || x.count > P) die(`SKEL level ${c.level}: 'PALR' ${r.count}, 'PALX' ${x.count}, ${P} skin joints`);
		const kd = plain(c, k), J = chunks[1].streams[0].count;
		for (let e = 0; kd && e < k.count; e++) {
			const v = kd.readUInt32LE(4 * e);
			if (v >= J || (e && v <= kd.readUInt32LE(4 * e - 4))) die(`SKEL level ${c.level}: kept joint ${e} is ${v}`);
		}
		const rd = plain(c, r);
		if (!rd) { palette.push(null); continue; }
		const kinds = [0, 0, 0];
		for (let e = 0; e < P; e++) {
			const v = rd.readUInt32LE(4 * e);
			if (v > P + x.count) die(`SKEL level ${c.level}: palette entry ${e} refers to ${v}, past ${P} + ${x.count}`);
			kinds[v === 0 ? 0 : v <= P ? 1 : 2]++;
		}
		palette.push(kinds);
	}
}

// Order: INFO, SKEL 0, skeleton levels coarsest first, then per rank from
// the coarsest (MESH level top - rank, then ANIM level top - rank of every
// clip in clip order: the coarsest levels of both layers first), DOC last.
const types = chunks.map((c) => c.type);
if (types[0] !== 'INFO' || types[1] !== 'SKEL' || chunks[1].level !== 0 || types[n - 1] !== 'DOC ') die(`order: ${types.join(',')}`);
let i = 2, last = Infinity;
for (; i < n && types[i] === 'SKEL'; i++) {
	if (!(chunks[i].level < last) || chunks[i].level === 0) die('skeleton levels not coarsest first');
	last = chunks[i].level;
}
const top = (t) => Math.max(-1, ...chunks.filter((c) => c.type === t).map((c) => c.level));
const meshTop = top('MESH'), animTop = top('ANIM');
last = -Infinity;
for (; i < n - 1; i++) {
	if (types[i] !== 'MESH' && types[i] !== 'ANIM') die(`chunk ${i}: ${types[i]} among the levels`);
	const c = chunks[i], key = (c.type === 'MESH' ? meshTop - c.level : animTop - c.level) * 1e6 + (c.type === 'ANIM' ? 1 + c.item : 0);
	if (!(key > last)) die(`chunk ${i}: ${c.type} level ${c.level} item ${c.item} out of order`);
	last = key;
}

// INFO.
const info = chunks[0], is = info.streams;
if (is[0].tag !== 'INFO' || is[0].count !== 1 || is[0].size !== 80 || is[1].tag !== 'NAME') die('INFO streams');
const r = b.subarray(info.offset + is[0].at, info.offset + is[0].at + 80);
const u = (k) => r.readUInt32LE(4 * k), f = (k) => r.readFloatLE(4 * k);
const names = b.subarray(info.offset + is[1].at, info.offset + is[1].at + is[1].count).toString('utf8').split('\0');
const out = {
	chunks: n, size: b.length,
	joints: u(0), skins: u(1), skeleton_levels: u(2), mesh_levels: u(3), clips: u(4), motion_levels: u(5), parts: u(6),
	name: names[0], clip_names: names.slice(1, 1 + u(4)),
	bounds_min: [f(8), f(9), f(10)], bounds_max: [f(11), f(12), f(13)], height: f(14), diagonal: f(15), first_drawable: u(16),
	max_vertex_count: u(17), // format 8.1: the largest mesh level's vertices
	count: {},
	codecs: [...new Set(chunks.map((c) => c.codec))].sort(),
	entropy: [...new Set(chunks.map((c) => c.entropy))].sort(),
	stream_codecs: [...new Set(chunks.flatMap((c) => c.streams.map((s) => s.codec)))].sort(),
	tags: [...new Set(chunks.flatMap((c) => c.streams.map((s) => s.tag)))].sort(),
	doc: chunks[n - 1].streams[0].count,
	palette,
	planes: chunks.reduce((a, c) => a + c.streams.filter((t) => t.codec === 4 || t.codec === 5).length, 0),
	// every weights stream stored without its sums, decoded: its count
	sums: chunks.reduce((a, c) => a + c.streams.filter((t) => t.codec === 6 && plain(c, t)).length, 0),
	toc: chunks.map((c) => `${c.type.trim()} ${c.level}/${c.item} ${c.crc.toString(16)}`),
};
for (const c of chunks) out.count[c.type.trim()] = (out.count[c.type.trim()] || 0) + 1;
if (out.count.SKEL !== out.skeleton_levels) die('SKEL chunks and INFO skeleton_levels');
if ((out.count.MESH || 0) !== out.mesh_levels) die('MESH chunks and INFO mesh_levels');
if ((out.count.ANIM || 0) !== out.clips * out.motion_levels) die('ANIM chunks and INFO clips x motion_levels');
if ((out.mesh_levels === 0 && out.max_vertex_count !== 0) || u(18) || u(19)) die('INFO max_vertex_count or reserved bytes');
if (out.first_drawable > b.length || out.first_drawable < chunks[1].offset + chunks[1].stored) die('first_drawable');
// Every coarsest level lies within first_drawable.
for (const c of chunks) {
	const coarsest = c.type === 'MESH' ? out.mesh_levels - 1 : c.type === 'ANIM' ? out.motion_levels - 1 : c.type === 'SKEL' ? out.skeleton_levels - 1 : -1;
	if (c.level === coarsest && c.offset + c.stored > out.first_drawable) die(`${c.type} level ${c.level} past first_drawable`);
	// a nested ANIM level builds on the clip's next coarser one, earlier in the file
	if (c.flags && !chunks.some((d) => d.type === 'ANIM' && d.item === c.item && d.level === c.level + 1 && d.offset < c.offset)) die(`ANIM level ${c.level} of clip ${c.item}: nested on a level the pack lacks`);
}
if (process.argv[3] === '--doc') {
	const d = chunks[n - 1], s = d.streams[0];
	if (s.tag !== 'GLB ' || s.codec !== 0) die('DOC stream');
	writeFileSync(process.argv[4], d.data.subarray(s.at, s.at + s.count));
}
console.log(JSON.stringify(out));
