/*
 * mlod_pack.h: the .mlod pack format (mlod(5)) and its one reader.
 *
 * This header owns the format: every constant, every byte layout and the
 * decoded view of each chunk. The bake side's writer (lib/pack) includes
 * it to write what this reader reads; the runtime (mlod_rt.h), mlod-pack
 * --info and -x read through it. It is C11, depends only on the core,
 * meshoptimizer's decoder and libzstd's (the entropy stage, format 5.0),
 * and never prints or exits.
 *
 * ------------------------------------------------------------------
 * File layout (format 8.1: 7.0 with the coarsest levels of every layer
 * first, mlod(5) Chunk order and streaming; 8.1 adds INFO's
 * max_vertex_count in bytes 8.0 reserved). Everything is little-endian.
 *
 *   header      32 bytes at offset 0
 *   TOC         chunk_count entries of 48 bytes, right after the header
 *   chunks      each starts on a 16-byte boundary (zero padding between),
 *               in TOC order, coarse to fine (below)
 *
 * Header:
 *   0  u8[4]  magic "MLOD"
 *   4  u16    major version (MLOD_PACK_MAJOR); a reader refuses a newer one,
 *             and one older than MLOD_PACK_MAJOR_OLDEST (1.x: MESH layout
 *             a, no decode path); 2.x is 3.x without MLOD_PART_LOCAL,
 *             the sequence codec and 'TBIT'; 2.x to 6.x store a
 *             skeleton level's palette as 'PALJ' and 'PALB' (7.0:
 *             'PALR' and 'PALX'); 2.x to 8.x store 'ROTQ' keys as they
 *             are and 'ROTD' differences not zigzagged (9.0: predicted,
 *             zigzagged)
 *   6  u16    minor version; a newer minor only adds what older readers skip
 *   8  u32    flags (0; a reader ignores bits it does not know)
 *  12  u32    chunk_count (at most MLOD_PACK_MAX_CHUNKS)
 *  16  u64    file_size: the whole file, header to the last chunk's end
 *  24  u32    CRC32 of the TOC bytes
 *  28  u32    CRC32 of header bytes 0..27
 *
 * TOC entry (48 bytes):
 *   0  u32    type (MLOD_CHUNK_*); a reader skips types it does not know
 *   4  u8     layer (MLOD_LAYER_*)
 *   5  u8     codec: bits 0-3 the codec of the chunk's streams
 *             (MLOD_CODEC_*); bits 4-7 the entropy stage over the whole
 *             chunk (MLOD_ENTROPY_*, format 5.0, 2 from 6.0; 0 before)
 *   6  u16    level: 0 the finest (the input as read), larger is coarser
 *   8  u16    item: the clip for MOTION chunks, else 0
 *  10  u16    flags (MLOD_PACK_CHUNK_NESTED for a nested MOTION level, else 0)
 *  12  u32    coded size: with an entropy stage, the stream container's
 *             bytes (what the stage decodes to: 4 to the raw size); else 0
 *  16  u64    offset of the chunk from the start of the file (16-aligned)
 *  24  u32    stored size in bytes
 *  28  u32    raw size: the chunk's size with every stream decoded
 *  32  u32    CRC32 (IEEE 802.3, as zlib's crc32) of the stored bytes
 *  36  f32    error: the level's measured error in scene units (0 for
 *             level 0 and for chunks that are not levels)
 *  40  f32    switch distance: the camera distance (scene units) from which
 *             this level is fine enough, at MLOD_PACK_FOV_Y and
 *             MLOD_PACK_LINES (the error projects to at most
 *             MLOD_PACK_PIXELS pixels); 0 for level 0
 *  44  u32    reserved (0)
 *
 * Chunk order: INFO, SKELETON, the skeleton levels coarsest first, then per
 * level from the coarsest to the finest: that mesh level and that motion
 * level of every clip; DOC last. A reader holding a prefix of the file has
 * every chunk whose end lies inside it, and so the coarse levels first;
 * mlod-pack --info says how many bytes the first drawable level needs.
 *
 * Chunk payload: a stream container; with entropy stage MLOD_ENTROPY_ZSTD,
 * one zstd frame of it that states its size (the coded size) and nothing
 * after it (mlod(5) ENTROPY STAGE). With MLOD_ENTROPY_ZSTD_PREFIX (format
 * 6.0: skeleton levels, MESH levels but the coarsest), the frame is coded
 * with the containers of chunks the level already needs as its prefix
 * (SKELETON's; the coarser MESH levels'), so a prefix of the file still
 * decodes every level it holds.
 *   u32 stream_count (at most MLOD_PACK_MAX_STREAMS)
 *   stream_count stream headers of 16 bytes:
 *     0 u32  tag (MLOD_STREAM_*, a fourcc)
 *     4 u32  element count
 *     8 u16  element size in bytes (1..256; a multiple of 4 for the meshopt
 *            vertex codec, 2 or 4 for the index and sequence codecs)
 *    10 u8   stream codec (MLOD_SCODEC_*; 4 and 5, byte planes, and 6,
 *            sums to 255, format 7.0)
 *    11 u8   reserved (0)
 *    12 u32  stored byte size
 *   then the streams' bytes in order, each padded with zeros to 4 bytes.
 * A stream's decoded size is count * element size, which a raw stream and
 * one in byte planes store. raw size in the TOC is
 * 4 + 16 * stream_count + the decoded sizes, each padded to 4.
 *
 * The chunk types and their streams, in this order:
 *
 * INFO (layer none, once): stream 'INFO', one element of
 *   sizeof(mlod_pack_info_rec) bytes; stream 'NAME', the string table
 *   (u8, NUL-separated, UTF-8): the character's and the clips' names.
 *   max_vertex_count (format 8.1, record bytes 68-71) is the largest sum
 *   of a MESH level's part records' vertex counts; the reader checks it
 *   against the TOC at decode (at most what the MESH chunks' raw sizes
 *   can hold: a level's vertices are among its indices, 2 bytes each at
 *   least, and among the 'POSQ' elements of it and the coarser levels, 8
 *   bytes each; a Draco level's at most 1024 times its
 *   container over 12 bytes of positions), every MESH level against it
 *   (the runtime before it allocates the level), and mlod_pack_check
 *   that the largest level has exactly it.
 *
 * SKELETON (layer skeleton, level 0, once): the full skeleton.
 *   'JNTS' joint records (mlod_pack_joint_rec), parents before children
 *   'NAME' the string table of joint names
 *   'SKIN' skin records (mlod_pack_skin_rec)
 *   'SKJT' u32 per skin joint, all skins in order: joint indices
 *   'IBMS' 16 f32 per skin joint: inverse bind matrices, column-major
 *
 * SKELETON level k >= 1: a nested level of the skeleton.
 *   'KEPT' u32 per kept joint, increasing: the full skeleton's joints it
 *          keeps (every root is kept). A kept joint's parent at this level
 *          is its nearest kept ancestor; its local transform folds the
 *          removed joints between them (mlod(5), SKELETON LEVELS).
 *   'PALR' u32 per skin joint (all skins in order, as 'SKJT'; format
 *          7.0): where the bind matrix to use with it comes from: 0 the
 *          joint's own 'IBMS' entry; v in 1..P (P: the skin joints of all
 *          skins) 'IBMS' entry v - 1, all skins in order; v > P 'PALX'
 *          matrix v - P - 1
 *   'PALX' 16 f32 per matrix (at most P; format 7.0): the bind matrices
 *          no 'IBMS' entry holds
 *   The decoded palette (mlod_pack_skel_level): per skin joint, the kept
 *   joint (full index) whose world matrix a vertex weighted to it follows
 *   at this level (the joint itself when kept, else its stand-in, the
 *   nearest kept ancestor: the reader derives it), and the bind matrix
 *   'PALR' names (the joint's own inverse bind when kept; else the
 *   stand-in's, or R(stand-in -> joint) * IBM(joint) when the stand-in is
 *   not in that skin), so that skinning with that palette equals skinning
 *   the level's transferred weights. (Writer's notes: when several
 *   removed joints of one skin share a stand-in that skin lacks, all take
 *   the R * IBM of the first of them in skin order, as fold.c's skin
 *   transfer does; R is in the rest pose. 'PALR' is 0 wherever the matrix
 *   has the bytes of the joint's own 'IBMS' entry, else the first entry
 *   that has them, else a 'PALX' matrix, each once in first-use order.)
 *   Formats 2.0 to 6.0 stored instead 'PALJ', u32 per skin joint: the
 *   stand-in (or the joint; the reader checks it is the nearest kept
 *   ancestor), then 'PALB', 16 f32 per skin joint: the bind matrices.
 *
 * MESH level k (layer mesh; level 0 is the input's meshes): one part per
 *   instance and triangle primitive, in instance then primitive order, the
 *   same parts at every level. Layout b2 (mlod(5) MESH levels): a part's
 *   levels share one buffer of quantised vertices on one grid, each vertex
 *   once, placed by the coarsest level that has it (coarsest level's
 *   first); level k's prefix is the vertices of levels k and coarser.
 *   MESH level k carries, per part, its block (the vertices the coarser
 *   levels lack: every vertex stream below has the block's count) and its
 *   indices into its prefix. A decode of level k reads every coarser MESH
 *   chunk's blocks too and gathers the vertices level k's indices use, in
 *   first-use order, renumbering the indices: the decoded mlod_pack_part is
 *   that level alone. A part's records at two levels differ only in
 *   vertex_count (the distinct prefix vertices its indices use: the
 *   decoded count), index_count, MLOD_PART_INDEX16, MLOD_PART_LOCAL and
 *   MLOD_PART_NEWBITS. With MLOD_PART_LOCAL (3.0) a part's level stores
 *   that decoded numbering itself: 'IMAP' (after 'INEW' with NEWBITS),
 *   then 'IDX ' below vertex_count.
 *   'PART' part records (mlod_pack_part_rec)
 *   then per part, the streams its flags name, in this order:
 *   'POSQ' u16[4] per vertex: position = min + q * scale (q[3] is 0)
 *   'NRMQ' i16[2] per vertex: octahedral unit normal, snorm16
 *   'TANQ' i16[4] per vertex: octahedral unit tangent (snorm16), then the
 *          handedness w as -32767 or 32767, then 0
 *   'UVQ0'.. u16[2] per vertex per UV set: uv = uv_min + q * uv_scale
 *   'COLQ' u8[4] per vertex: colour set 0, unorm8 RGBA
 *   'JNT8' u8[4] or 'JN16' u16[4] per vertex: joints of the part's skin
 *          (indices into that skin's joint list of the full skeleton)
 *   'WGT8' u8[4] per vertex: weights, unorm8, summing exactly to 255
 *   'INEW' with MLOD_PART_NEWBITS: u32 words, (vertex_count + 31) / 32 of
 *          them: bit v % 32 of word v / 32 set says the level's vertex v
 *          is the next vertex of its own block (from the block's first)
 *   'IMAP' with MLOD_PART_LOCAL: u32 (u16 with INDEX16) per level vertex
 *          whose 'INEW' bit is clear, in order: its prefix vertex (every
 *          vertex without NEWBITS); the stream codec may be
 *          MLOD_SCODEC_MESHOPT_SEQUENCE
 *   'IDX ' u32 (or u16, element size 2) per index: triangles, each below
 *          the prefix's vertex count (the writer uses u16 up to 65536);
 *          with MLOD_PART_LOCAL below vertex_count (the level's own
 *          numbering: the writer stores whichever codes smaller)
 *   'MTPQ' per morph target: i16[4] per vertex position delta
 *          = q * target_scale[t] (q[3] is 0); 'MTSC' f32 per target before
 *          them: the targets' scales
 *   (Writer's notes: the grid is the union of the levels' boxes in level
 *   0's steps (or the union's 16-bit steps where it is wider than 65535 of
 *   them), morph deltas scaled by the largest of any level; a
 *   rigid part (joint >= 0, skin -1) has no joints or weights and follows
 *   its joint through offset; a vertex's 4 largest influences over all
 *   its glTF weight sets are kept; 'PART' comes first but is filled last.)
 *
 * MOTION level k of clip c (layer motion, item c; level 0 is the clip as
 *   read, every key, a constant channel as one): the channels of one clip
 *   on the full skeleton. Every
 *   clip has INFO motion_levels levels: a clip with fewer (too few frames,
 *   no level within a bound) repeats its coarsest one.
 *   'CHAN' channel records (mlod_pack_channel_rec)
 *   'STEP' one f64: the chunk's time step in seconds, 0 for f32 times
 *   then the key times, one stream: the chunk's distinct key-time arrays
 *   one after the other, in the order the channels first refer to them
 *   (channel rec.time: its array's index; channel 0 refers to array 0,
 *   each later channel to an earlier array or the next one; an array's
 *   length is the key_count of the channels referring to it):
 *   'TIME' f32 per key (seconds), when step is 0, or
 *   'TICK' u16 (element size 2) or u32 (element size 4) per key, when
 *          step > 0: each array's first tick, then each next tick minus
 *          the one before (every tick below 2^32); time =
 *          (float)((double)tick * step): the key time read, or within
 *          2^-20 * max(|t|, step) of it (mlod(5), QUANTISATION); or
 *   'TBIT' u32 words, when step > 0 (format 3.0; the writer stores the
 *          smaller of the two): each array's first tick (one word per
 *          array), then one bit stream (bit b is bit b % 32 of word
 *          arrays + b / 32): per array in order, a bit per tick after its
 *          first, set where the array has a key, ending with its last
 *          key's bit; the next array's bits follow at once; exactly as
 *          many words as that takes
 *   then the values, three streams, each holding the keys of its
 *   channels one channel after the other in channel order (possibly 0
 *   elements):
 *   'ROTQ' i16[4] per key of every non-cubic rotation without a base key
 *          (below): the components but the one at index i, in index
 *          order, on the lattice of normalised shorts (value = q /
 *          32767), each stored as q >> shift, then i + 4 * shift (shift
 *          0..MLOD_PACK_ROTQ_SHIFT_MAX; 0 before format 4.0, where the
 *          element is i, 0..3); the reader rebuilds component i as
 *          lrint(sqrt(max(0, 1 - s)) * 32767) / 32767, s the sum of the
 *          others' squares (each the f32 nearest q / 32767, summed in f64);
 *          Format 9.0: every key but a channel's first stores, instead
 *          of its three components, each one's difference to its
 *          prediction (mlod_pack_rotq_predict: from the channel's key
 *          before and its next key with a base key), wrapped to 16 bits
 *          and zigzagged (mlod_pack_zigzag16); the element's i + 4 *
 *          shift as before;
 *   'ROTD' i16[4] per key of every non-cubic rotation with a base key: its
 *          lattice integers minus the base key's, wrapped to 16 bits
 *          (format 9.0: then zigzagged);
 *          after either, a key is negated when its dot product with the
 *          channel's key before is negative (q and -q are one rotation)
 *          (mlod_pack_rotq_key). (Format 1.0 stored the four components.)
 *   'ROTF' f32[4], 3 per key (in-tangent, value, out-tangent), of every
 *          cubic-spline rotation;
 *   'VEC3' f32[3] per key (3 per key for cubic splines) of every
 *          translation and scale without a base key;
 *   'VECD' u32[3] per key of every translation and scale with a base key
 *          (non-cubic): its f32 bit patterns minus the base key's,
 *          wrapped to 32 bits.
 *   A chunk with TOC flag MLOD_PACK_CHUNK_NESTED builds on the clip's
 *   level + 1 (which exists and stands before it): a rotation key has a
 *   base key when that level's non-cubic rotation channel of the joint
 *   has a key at exactly the same (decoded) time; a translation or scale
 *   key when that level's non-cubic channel of the joint and path does.
 *   The writer nests every
 *   level but the coarsest and keeps the clip's own values at every level.
 *   (Writer's notes: a non-cubic channel whose keys all hold one value is
 *   stored as one key at its last time, which keeps the clip's duration;
 *   key times go as ticks when every one is a multiple of one step within
 *   that tolerance, as sampled clips' are, an exact step preferred.)
 *
 * DOC (layer none, once, last): stream 'GLB ': the input glb without the
 *   meshes' geometry and the joint clips, which the levels hold: materials,
 *   textures, images, samplers, names, extras, extensions, the node tree,
 *   skins and everything else the input carried. The runtime skips it;
 *   mlod-pack -x rebuilds a glb from it and the levels. (Writer's note:
 *   as mlod_gltf_strip_levels makes it: primitives keep mode, material,
 *   extensions and extras with empty attributes, no indices, no targets,
 *   but for meshes on nodes the default scene does not show, which stay
 *   whole;
 *   animations keep every channel but the joints' translation, rotation
 *   and scale, which the MOTION chunks hold (animations left empty go:
 *   animation indices change); MSFT_lod goes, its level nodes stay
 *   without mesh or skin; node, mesh, skin and material indices hold, so
 *   'PART' node, mesh and material and 'SKIN' gltf_index refer to it. A
 *   document with an extension that may refer to accessors keeps every
 *   index (mlod_gltf_keep_indices): only what sits at the ends of its
 *   arrays goes, the stages' records and MSFT_lod.)
 *
 * Precisions the reader (lib/rt/rd_*.c) checks, added with it; they make
 * explicit what the text above implies and change no layout:
 * - file_size is exactly the last chunk's end (the TOC's end without
 *   chunks): no bytes after the last chunk.
 * - The known chunk types appear in the order above, each (type, level,
 *   item) at most once: INFO, DOC and every SKELETON and MESH have item 0,
 *   INFO and DOC level 0; only MESH chunks may use the Draco codec. Chunks
 *   of unknown types may stand anywhere. INFO's level counts match the TOC.
 * - A chunk of codec none has only raw streams; a chunk's stored size is
 *   exactly 4 + 16 * stream_count + its streams' stored sizes, each padded
 *   to 4 (and its raw size as said above).
 * - INFO 'NAME': the clips' names follow the character's name (at
 *   rec.name), one after the other, in clip order.
 * - MESH: 'POSQ' and 'IDX ' are always there (possibly with 0 elements);
 *   every MESH level from the coarsest to k is in the TOC when k decodes;
 *   'MTSC' and the 'MTPQ' streams only when target_count > 0. pos_scale
 *   and the target scales are >= 0, and every range (min + 65535 * scale)
 *   finite; unknown part flags are refused. Normals and
 *   tangents use the octahedral map: x = q0 / 32767, y = q1 / 32767 (each
 *   clamped to -1), z = 1 - |x| - |y|; where z < 0, (x, y) becomes
 *   ((1 - |y|) * sign x, (1 - |x|) * sign y) with sign 0 = +1; then the
 *   vector is normalised. 'TANQ' w is exactly -32767 or 32767.
 * - MOTION: key times are finite and strictly increasing; a joint has at
 *   most one channel per path; each value stream's count is its
 *   channels' keys (x3 for cubic), the time stream's the arrays' keys;
 *   every channel referring to an array has its key count; 'STEP' is
 *   finite and >= 0.
 */
#ifndef MLOD_PACK_H
#define MLOD_PACK_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "mlod_core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define MLOD_PACK_MAGIC "MLOD"
#define MLOD_PACK_MAJOR 9
#define MLOD_PACK_MAJOR_OLDEST 2 /* the oldest major this reader reads */
#define MLOD_PACK_MINOR 0 /* 9.0: predicted ROTQ keys; 8.1: INFO's max_vertex_count */
#define MLOD_PACK_HEADER_SIZE 32
#define MLOD_PACK_TOC_ENTRY_SIZE 48
#define MLOD_PACK_ALIGN 16
#define MLOD_PACK_MAX_CHUNKS 65536
#define MLOD_PACK_MAX_STREAMS 65536
#define MLOD_PACK_MAX_UV 4

/* The switch distance's view: a level switches in where its error spans
 * MLOD_PACK_PIXELS pixels on a screen of MLOD_PACK_LINES lines with a
 * vertical field of view of MLOD_PACK_FOV_Y degrees. */
#define MLOD_PACK_FOV_Y 60.0
#define MLOD_PACK_LINES 1080.0
#define MLOD_PACK_PIXELS 1.0

#define MLOD_FOURCC(a, b, c, d) \
	((uint32_t)(uint8_t)(a) | (uint32_t)(uint8_t)(b) << 8 | (uint32_t)(uint8_t)(c) << 16 | (uint32_t)(uint8_t)(d) << 24)

/* Chunk types. */
#define MLOD_CHUNK_INFO MLOD_FOURCC('I', 'N', 'F', 'O')
#define MLOD_CHUNK_SKELETON MLOD_FOURCC('S', 'K', 'E', 'L')
#define MLOD_CHUNK_MESH MLOD_FOURCC('M', 'E', 'S', 'H')
#define MLOD_CHUNK_MOTION MLOD_FOURCC('A', 'N', 'I', 'M')
#define MLOD_CHUNK_DOC MLOD_FOURCC('D', 'O', 'C', ' ')

typedef enum mlod_pack_layer {
	MLOD_LAYER_NONE = 0,
	MLOD_LAYER_SKELETON = 1,
	MLOD_LAYER_MESH = 2,
	MLOD_LAYER_MOTION = 3
} mlod_pack_layer;

/* A chunk's codec (TOC), naming what its streams use. */
typedef enum mlod_pack_codec {
	MLOD_CODEC_NONE = 0,    /* every stream raw */
	MLOD_CODEC_MESHOPT = 1, /* meshoptimizer's vertex and index codecs */
	MLOD_CODEC_DRACO = 2    /* Draco's mesh codec (mesh chunks) */
} mlod_pack_codec;

/* A chunk's entropy stage (format 5.0; TOC codec byte bits 4-7): a
 * general-purpose compressor over the chunk's whole stream container, as
 * its codec made it. The TOC's coded size (bytes 12-15) is then the
 * container's size, at least 4 and at most the raw size; the stored bytes
 * are one zstd frame that says that size. INFO never has one. */
#define MLOD_ENTROPY_NONE 0
#define MLOD_ENTROPY_ZSTD 1
/* Format 6.0: one zstd frame coded with a prefix (ZSTD_CCtx_refPrefix) of
 * stream containers as the reader has them after undoing their own stage:
 * a skeleton level's, SKELETON's; a MESH level's (not the coarsest), every
 * coarser MESH level's, coarsest first, one after the other. Only on those
 * chunks; at most MLOD_PACK_MAX_PREFIX bytes. */
#define MLOD_ENTROPY_ZSTD_PREFIX 2
#define MLOD_PACK_MAX_PREFIX ((uint64_t)1 << 26)

/* A stream's codec. */
#define MLOD_SCODEC_RAW 0
#define MLOD_SCODEC_MESHOPT_VERTEX 1 /* meshopt_decodeVertexBuffer */
#define MLOD_SCODEC_MESHOPT_INDEX 2  /* meshopt_decodeIndexBuffer */
#define MLOD_SCODEC_MESHOPT_SEQUENCE 3 /* meshopt_decodeIndexSequence (format 3.0) */
/* Format 7.0: the decoded bytes in byte planes (count * element size bytes
 * stored, as raw): byte j of element k stored at j * count + k; with
 * DELTA, each stored byte is that byte minus the same byte of element
 * k - 1 (0 for k = 0), modulo 256. For the entropy stage after it. */
#define MLOD_SCODEC_PLANES 4
#define MLOD_SCODEC_PLANES_DELTA 5
/* Format 7.0: elements of 4 bytes whose bytes sum to 255 (unorm8 weights),
 * each stored as its first three bytes (count * 3 bytes); the reader
 * rebuilds the fourth as 255 minus their sum. */
#define MLOD_SCODEC_SUM255 6

/* Stream tags. */
#define MLOD_STREAM_INFO MLOD_FOURCC('I', 'N', 'F', 'O')
#define MLOD_STREAM_NAME MLOD_FOURCC('N', 'A', 'M', 'E')
#define MLOD_STREAM_JNTS MLOD_FOURCC('J', 'N', 'T', 'S')
#define MLOD_STREAM_SKIN MLOD_FOURCC('S', 'K', 'I', 'N')
#define MLOD_STREAM_SKJT MLOD_FOURCC('S', 'K', 'J', 'T')
#define MLOD_STREAM_IBMS MLOD_FOURCC('I', 'B', 'M', 'S')
#define MLOD_STREAM_KEPT MLOD_FOURCC('K', 'E', 'P', 'T')
#define MLOD_STREAM_PALJ MLOD_FOURCC('P', 'A', 'L', 'J')
#define MLOD_STREAM_PALB MLOD_FOURCC('P', 'A', 'L', 'B')
#define MLOD_STREAM_PALR MLOD_FOURCC('P', 'A', 'L', 'R') /* format 7.0 */
#define MLOD_STREAM_PALX MLOD_FOURCC('P', 'A', 'L', 'X') /* format 7.0 */
#define MLOD_STREAM_PART MLOD_FOURCC('P', 'A', 'R', 'T')
#define MLOD_STREAM_POSQ MLOD_FOURCC('P', 'O', 'S', 'Q')
#define MLOD_STREAM_NRMQ MLOD_FOURCC('N', 'R', 'M', 'Q')
#define MLOD_STREAM_TANQ MLOD_FOURCC('T', 'A', 'N', 'Q')
#define MLOD_STREAM_UVQ0 MLOD_FOURCC('U', 'V', 'Q', '0') /* set s: 'U','V','Q','0' + s */
#define MLOD_STREAM_COLQ MLOD_FOURCC('C', 'O', 'L', 'Q')
#define MLOD_STREAM_JNT8 MLOD_FOURCC('J', 'N', 'T', '8')
#define MLOD_STREAM_JN16 MLOD_FOURCC('J', 'N', '1', '6')
#define MLOD_STREAM_WGT8 MLOD_FOURCC('W', 'G', 'T', '8')
#define MLOD_STREAM_IDX MLOD_FOURCC('I', 'D', 'X', ' ')
#define MLOD_STREAM_INEW MLOD_FOURCC('I', 'N', 'E', 'W')
#define MLOD_STREAM_IMAP MLOD_FOURCC('I', 'M', 'A', 'P')
#define MLOD_STREAM_MTSC MLOD_FOURCC('M', 'T', 'S', 'C')
#define MLOD_STREAM_MTPQ MLOD_FOURCC('M', 'T', 'P', 'Q')
#define MLOD_STREAM_DRCO MLOD_FOURCC('D', 'R', 'C', 'O') /* a part's level as one Draco mesh (codec draco) */
#define MLOD_STREAM_CHAN MLOD_FOURCC('C', 'H', 'A', 'N')
#define MLOD_STREAM_STEP MLOD_FOURCC('S', 'T', 'E', 'P')
#define MLOD_STREAM_TIME MLOD_FOURCC('T', 'I', 'M', 'E')
#define MLOD_STREAM_TICK MLOD_FOURCC('T', 'I', 'C', 'K')
#define MLOD_STREAM_TBIT MLOD_FOURCC('T', 'B', 'I', 'T')
#define MLOD_STREAM_ROTQ MLOD_FOURCC('R', 'O', 'T', 'Q')
/* TOC flags of a MOTION chunk: its rotation keys build on the clip's next
 * coarser level (level + 1, earlier in the file). */
#define MLOD_PACK_CHUNK_NESTED 1u
/* At most this many nested levels in a row (a reader refuses a longer
 * chain: each load decodes it). */
#define MLOD_PACK_MAX_NESTING 64

/* The largest lattice shift of a 'ROTQ' key (format 4.0): its three
 * stored components count steps of 2^shift lattice units. */
#define MLOD_PACK_ROTQ_SHIFT_MAX 8

/* One 'ROTQ' key as lattice integers (value = n / 32767): e the stored
 * element; base, for a key whose time the base channel also has, that
 * key as returned (else NULL): n = base + e, each wrapped to 16 bits;
 * else, with i = e[3] & 3 and shift = e[3] >> 2 (0 before format 4.0;
 * e[3] 0 to 4 * MLOD_PACK_ROTQ_SHIFT_MAX + 3, each |e[j]| at most 32767
 * >> shift), the three components but i's in index order, each e[j] *
 * 2^shift, the one at i rebuilt non-negative. prev: the key before as
 * returned (NULL for the first): n is negated when its dot product with
 * prev is negative. The writer and the reader share it. */
static inline void mlod_pack_rotq_key(const int16_t e[4], const int16_t *base, const int16_t *prev, int16_t n[4])
{
	if (base) {
		for (int c = 0; c < 4; c++)
			n[c] = (int16_t)(uint16_t)((uint16_t)base[c] + (uint16_t)e[c]);
	} else {
		int big = e[3] & 3, shift = (e[3] >> 2) & 15;
		double sum = 0.0;
		for (int c = 0, j = 0; c < 4; c++)
			if (c != big) {
				long v = (long)e[j++] * (1L << shift);
				v = v > 32767 ? 32767 : v < -32767 ? -32767 : v;
				float f = (float)((double)v / 32767.0);
				n[c] = (int16_t)v;
				sum += (double)f * (double)f;
			}
		n[big] = (int16_t)lrint(sqrt(sum < 1.0 ? 1.0 - sum : 0.0) * 32767.0);
	}
	if (prev) {
		int64_t dot = 0;
		for (int c = 0; c < 4; c++)
			dot += (int64_t)n[c] * prev[c];
		for (int c = 0; dot < 0 && c < 4; c++)
			n[c] = (int16_t)-n[c];
	}
}
/* Format 9.0: a 16-bit difference d as stored (zigzag: small magnitudes
 * of either sign to small numbers, 0 -1 1 -2 to 0 1 2 3), and back. */
static inline int16_t mlod_pack_zigzag16(int16_t d)
{
	return (int16_t)(uint16_t)((uint16_t)((uint16_t)d << 1) ^ (uint16_t)(d < 0 ? 0xFFFFu : 0u));
}
static inline int16_t mlod_pack_unzigzag16(int16_t z)
{
	uint16_t u = (uint16_t)z;
	return (int16_t)(uint16_t)((uint16_t)(u >> 1) ^ (uint16_t)(u & 1 ? 0xFFFFu : 0u));
}

/* Format 9.0: what a 'ROTQ' key's three stored components are taken
 * from. e[3] as stored (index i = e[3] & 3, shift = e[3] >> 2), prev the
 * channel's key before as returned, next (or NULL) the channel's next key
 * that has a base key, as mlod_pack_rotq_key returns it without a key
 * before (prev NULL), and f = (t - t_prev) / (t_next - t_prev) in double
 * from the keys' f32 times (a subtraction and a division: IEEE double
 * rounds them alike everywhere). The prediction is in integers, so that
 * every compiler and flag set (fused multiply-adds) gets the same bits:
 * F = lrint(f * 65536) (0..65536), P[c] = prev[c] * 65536 + (s next[c] -
 * prev[c]) * F in int64 (s = -1 when next's dot product with prev is
 * negative, else 1; P[c] = prev[c] * 65536 without next), negated when
 * P[i] < 0; pred[j] = P[c] / 2^(16 + shift) rounded half away from zero,
 * within +-32767, for the three components c but i, in index order. The
 * stored e[j] is the key's minus pred[j], wrapped to 16 bits and
 * zigzagged (mlod_pack_zigzag16). A channel's first key stores its
 * components as they are. The writer and the reader share it. */
static inline void mlod_pack_rotq_predict(const int16_t e3, const int16_t prev[4], const int16_t *next, double f,
                                          int16_t pred[3])
{
	int big = e3 & 3, shift = (e3 >> 2) & 15;
	int64_t P[4], dot = 0;
	const int64_t F = next && f > 0.0 ? (f < 1.0 ? (int64_t)lrint(f * 16777216.0) : 16777216) : 0;
	for (int c = 0; next && c < 4; c++)
		dot += (int64_t)prev[c] * next[c];
	for (int c = 0; c < 4; c++) {
		const int64_t n = next ? (dot < 0 ? -(int64_t)next[c] : (int64_t)next[c]) : prev[c];
		P[c] = (int64_t)prev[c] * 16777216 + (n - prev[c]) * F;
	}
	const int neg = P[big] < 0;
	const int64_t D = (int64_t)1 << (24 + shift);
	for (int c = 0, j = 0; c < 4; c++)
		if (c != big) {
			const int64_t v = neg ? -P[c] : P[c], a = v < 0 ? -v : v;
			int64_t r = (a + D / 2) / D;
			if (r > 32767)
				r = 32767;
			pred[j++] = (int16_t)(v < 0 ? -r : r);
		}
}
#define MLOD_STREAM_ROTF MLOD_FOURCC('R', 'O', 'T', 'F')
#define MLOD_STREAM_VEC3 MLOD_FOURCC('V', 'E', 'C', '3')
#define MLOD_STREAM_ROTD MLOD_FOURCC('R', 'O', 'T', 'D')
#define MLOD_STREAM_VECD MLOD_FOURCC('V', 'E', 'C', 'D')
#define MLOD_STREAM_GLB MLOD_FOURCC('G', 'L', 'B', ' ')

/* ------------------------------------------------------------------ */
/* Fixed records (little-endian, no padding: every field is 4 bytes)   */
/* ------------------------------------------------------------------ */

/* INFO: the whole character. */
typedef struct mlod_pack_info_rec {
	uint32_t joint_count;
	uint32_t skin_count;
	uint32_t skeleton_levels;  /* counting level 0 */
	uint32_t mesh_levels;      /* counting level 0; 0 without meshes */
	uint32_t clip_count;
	uint32_t motion_levels;    /* per clip, counting level 0; 0 without clips */
	uint32_t instance_count;   /* parts of mesh level 0 */
	uint32_t name;             /* the character's name: offset in 'NAME' */
	float bounds_min[3];       /* rest pose of level 0, scene units */
	float bounds_max[3];
	float height;              /* the skeleton height (mlod(5)) */
	float diagonal;            /* of the bounds */
	uint32_t first_drawable;   /* bytes of the file that hold the coarsest
	                            * skeleton, mesh and motion levels (INFO,
	                            * SKELETON, and the coarsest level of each
	                            * layer, of every clip for motion) */
	uint32_t max_vertex_count; /* format 8.1: the most vertices of any mesh
	                            * level, all parts (the sum of its part
	                            * records' vertex counts: what
	                            * mlod_rt_mesh_vertex_count gives for it),
	                            * 0 without meshes; reserved (0) before 8.1,
	                            * and a reader gives 0 for an older pack
	                            * (mlod_pack_has_max_vertices) */
	uint32_t reserved[2];
} mlod_pack_info_rec;

/* 1 when the pack's INFO has max_vertex_count (format 8.1 and later). */
#define MLOD_PACK_MINOR_MAX_VERTICES 1
static inline int mlod_pack_version_has_max_vertices(unsigned major, unsigned minor)
{
	return major > 8 || (major == 8 && minor >= MLOD_PACK_MINOR_MAX_VERTICES);
}

/* SKELETON 'JNTS'. */
typedef struct mlod_pack_joint_rec {
	int32_t parent;            /* -1 for a root */
	uint32_t name;             /* offset in 'NAME' */
	float t[3], r[4], s[3];    /* rest TRS, r as x, y, z, w */
	float base[16];            /* roots: the non-joint ancestors' world transform; identity otherwise */
	int32_t node;              /* glTF node of the input, or -1 */
} mlod_pack_joint_rec;

/* SKELETON 'SKIN'. */
typedef struct mlod_pack_skin_rec {
	uint32_t joint_count;      /* entries in 'SKJT' and 'IBMS' */
	uint32_t name;             /* offset in 'NAME' */
	int32_t gltf_index;        /* the input's glTF skin, or -1 */
} mlod_pack_skin_rec;

/* MESH 'PART' flags. */
#define MLOD_PART_NORMALS 0x1u
#define MLOD_PART_TANGENTS 0x2u
#define MLOD_PART_COLORS 0x4u
#define MLOD_PART_SKINNED 0x8u    /* joints and weights */
#define MLOD_PART_JOINTS16 0x10u  /* 'JN16' instead of 'JNT8' */
#define MLOD_PART_INDEX16 0x20u   /* 'IDX ' (and 'IMAP') elements are u16 */
#define MLOD_PART_LOCAL 0x40u     /* 'IMAP', then 'IDX ' in the level's own numbering (3.0) */
#define MLOD_PART_NEWBITS 0x80u   /* with LOCAL: 'INEW' before 'IMAP' (3.0) */

typedef struct mlod_pack_part_rec {
	uint32_t instance;         /* the character's instance */
	int32_t node;              /* its glTF node, or -1 */
	int32_t mesh;              /* its glTF mesh, or -1 */
	uint32_t primitive;        /* the primitive within that mesh */
	int32_t skin;              /* skin index (SKELETON), or -1 */
	int32_t joint;             /* rigid attachment joint, or -1 */
	int32_t material;          /* glTF material of the input, or -1 */
	uint32_t flags;            /* MLOD_PART_* */
	uint32_t vertex_count;
	uint32_t index_count;      /* a multiple of 3; 0 (and vertex_count 0): no triangle left at the level */
	uint32_t uv_sets;          /* 0..MLOD_PACK_MAX_UV */
	uint32_t target_count;     /* morph targets (positions only) */
	float offset[16];          /* mlod_instance.offset */
	float pos_min[3], pos_scale[3];
	float uv_min[MLOD_PACK_MAX_UV][2], uv_scale[MLOD_PACK_MAX_UV][2];
} mlod_pack_part_rec;

/* MOTION 'CHAN'. */
typedef struct mlod_pack_channel_rec {
	uint32_t joint;            /* full skeleton joint */
	uint32_t path;             /* 0 translation, 1 rotation, 2 scale (mlod_path) */
	uint32_t interp;           /* 0 linear, 1 step, 2 cubic spline (mlod_interp) */
	uint32_t key_count;
	uint32_t time;             /* its key-time array: index in first-use order (mlod(5)) */
} mlod_pack_channel_rec;

/* The MOTION chunk's clip: INFO 'NAME' holds the clip names, after the
 * character's (the strings that follow the one at rec.name, one per clip),
 * in clip order; each clip's duration is its largest key time. */

/* ------------------------------------------------------------------ */
/* The reader                                                          */
/* ------------------------------------------------------------------ */

/* One TOC entry, as read. */
typedef struct mlod_pack_chunk {
	uint32_t type;
	uint8_t layer, codec;      /* codec: the TOC byte's bits 0-3 */
	uint8_t entropy;           /* the TOC codec byte's bits 4-7 (MLOD_ENTROPY_*; format 5.0) */
	uint32_t coded_size;       /* with an entropy stage, the container's bytes (TOC bytes 12-15), else 0 */
	uint16_t level, item, flags;
	uint64_t offset;
	uint32_t stored_size, raw_size, crc;
	float error, distance;
} mlod_pack_chunk;

/* The reader's allocator (the runtime passes its own, mlod_rt_allocator's
 * callbacks): malloc(user, size) returns NULL on failure, free(user, p)
 * takes what it returned. Either NULL (a zeroed struct): malloc and free. */
typedef struct mlod_pack_alloc {
	void *(*malloc)(void *user, size_t size);
	void (*free)(void *user, void *p);
	void *user;
} mlod_pack_alloc;

/* An opened pack: the header and the TOC, checked (sizes, offsets,
 * alignment, order, CRCs of header and TOC; chunk CRCs are checked when a
 * chunk is decoded). Chunks of unknown types are kept in the TOC and
 * skipped by everything else. */
typedef struct mlod_pack {
	uint16_t major, minor;
	uint32_t flags;
	uint64_t file_size;
	uint32_t chunk_count;
	mlod_pack_chunk *chunks;
	mlod_pack_alloc alloc;     /* the TOC's, and every decode's from this pack */
	void *zstd;                /* the entropy stage's decoder, made by open with alloc when
	                            * a chunk has the zstd stage (else NULL), freed by close.
	                            * The decodes of one opened pack share it: run them on one
	                            * thread at a time (open the pack once per thread else). */
} mlod_pack;

/* Parses and checks the header and TOC from the first bytes of a file
 * (size >= 32 + 48 * chunk_count; the chunks need not be there).
 * MLOD_ERR_PARSE with a message for anything malformed,
 * MLOD_ERR_UNSUPPORTED for a newer major version. Release with
 * mlod_pack_close. mlod_pack_open_alloc allocates the TOC, and every
 * chunk decoded from the pack later, with alloc (NULL: malloc and free). */
mlod_result mlod_pack_open(const void *data, size_t size, mlod_pack *out, mlod_error *err);
mlod_result mlod_pack_open_alloc(const void *data, size_t size, const mlod_pack_alloc *alloc, mlod_pack *out,
                                 mlod_error *err);
void mlod_pack_close(mlod_pack *p);
/* The bytes the pack's zstd decoder holds from open to close (0 without
 * one), for a caller that counts its memory. */
size_t mlod_pack_decoder_bytes(const mlod_pack *p);

/* The CRC32 the format uses. */
uint32_t mlod_pack_crc32(uint32_t crc, const void *data, size_t size);

/* Decoded chunks. Each decode checks the chunk's CRC and every size,
 * count and index, and fails with MLOD_ERR_PARSE naming the chunk
 * ("MESH level 2: ...") rather than read out of bounds. Everything a
 * decoded chunk points to lives in one allocation owned by it (block),
 * made with the pack's allocator, which the block records; release with
 * the matching *_free (which accepts a zeroed struct), which frees it with
 * that allocator. */

typedef struct mlod_pack_info {
	mlod_pack_info_rec rec;    /* max_vertex_count 0 in a pack older than 8.1 */
	const char *name;          /* the character's */
	const char **clip_names;   /* clip_count */
	void *block;
	int has_max_vertices;      /* 1 when the pack states rec.max_vertex_count (format 8.1 on);
	                            * last, so the members before it keep their offsets */
} mlod_pack_info;

typedef struct mlod_pack_skeleton {
	uint32_t joint_count;
	const mlod_pack_joint_rec *joints;
	const char **joint_names;
	uint32_t skin_count;
	const mlod_pack_skin_rec *skins;
	const char **skin_names;
	const uint32_t **skin_joints;   /* per skin: joint_count joint indices */
	const float **inverse_bind;     /* per skin: 16 * joint_count */
	void *block;
} mlod_pack_skeleton;

typedef struct mlod_pack_skel_level {
	uint32_t kept_count;
	const uint32_t *kept;
	uint32_t palette_size;          /* skin joints over all skins */
	const uint32_t *palette_joint;
	const float *palette_bind;      /* 16 per palette entry */
	void *block;
} mlod_pack_skel_level;

/* A decoded part: attributes dequantised to floats. */
typedef struct mlod_pack_part {
	mlod_pack_part_rec rec;
	float *positions;               /* 3 per vertex */
	float *normals;                 /* 3 per vertex, or NULL */
	float *tangents;                /* 4 per vertex, or NULL */
	float *uvs[MLOD_PACK_MAX_UV];   /* 2 per vertex */
	float *colors;                  /* 4 per vertex, or NULL */
	uint16_t *joints;               /* 4 per vertex, or NULL */
	float *weights;                 /* 4 per vertex, summing to 1, or NULL */
	uint32_t *indices;
	float **targets;                /* target_count arrays of 3 per vertex */
} mlod_pack_part;

typedef struct mlod_pack_mesh {
	uint32_t part_count;
	mlod_pack_part *parts;
	void *block;
} mlod_pack_mesh;

typedef struct mlod_pack_channel {
	mlod_pack_channel_rec rec;
	const float *times;             /* key_count (shared by channels with one time array) */
	float *values;                  /* 3 or 4 per key (x3 for cubic spline), dequantised */
} mlod_pack_channel;

typedef struct mlod_pack_motion {
	uint32_t channel_count;
	mlod_pack_channel *channels;
	float duration;
	void *block;
} mlod_pack_motion;

/* data holds at least the chunk's bytes at its offset (a whole file, or
 * the prefix that ends at or after the chunk). */
mlod_result mlod_pack_decode_info(const mlod_pack *p, const void *data, size_t size, mlod_pack_info *out,
                                  mlod_error *err);
mlod_result mlod_pack_decode_skeleton(const mlod_pack *p, const void *data, size_t size,
                                      mlod_pack_skeleton *out, mlod_error *err);
/* skel is the decoded full skeleton the level refers to (required for a
 * skeleton level; for a mesh or motion level, NULL stands for a character
 * without joints and skins, and any reference to one then fails). */
mlod_result mlod_pack_decode_skel_level(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                        const mlod_pack_skeleton *skel, mlod_pack_skel_level *out,
                                        mlod_error *err);
mlod_result mlod_pack_decode_mesh(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                  const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err);
mlod_result mlod_pack_decode_motion(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                    const mlod_pack_skeleton *skel, mlod_pack_motion *out, mlod_error *err);
/* A MESH level needs the blocks of every coarser MESH level (layout b2):
 * mlod_pack_decode_mesh reads them from data (a prefix that holds the
 * chunk holds them too). mlod_pack_decode_mesh_fetch reads each chunk
 * through fetch instead, coarsest first: fetch(user, chunk, &bytes, err)
 * sets bytes to the chunk's stored_size bytes (valid until the next call)
 * or fails with a message; the decode checks them like any chunk's. */
typedef mlod_result (*mlod_pack_fetch_fn)(void *user, uint32_t chunk, const void **bytes, mlod_error *err);
mlod_result mlod_pack_decode_mesh_fetch(const mlod_pack *p, uint32_t chunk, mlod_pack_fetch_fn fetch, void *user,
                                        const mlod_pack_skeleton *skel, mlod_pack_mesh *out, mlod_error *err);
/* A MOTION chunk with MLOD_PACK_CHUNK_NESTED builds on the clip's next
 * coarser level: mlod_pack_decode_motion decodes that level (and what it
 * builds on) from data, which must then hold it too (a whole file or a
 * prefix); mlod_pack_decode_motion_on takes it decoded instead (base: the
 * clip's level + 1, required for a nested chunk, else ignored), as a
 * runtime that keeps it does. */
mlod_result mlod_pack_decode_motion_on(const mlod_pack *p, uint32_t chunk, const void *data, size_t size,
                                       const mlod_pack_skeleton *skel, const mlod_pack_motion *base,
                                       mlod_pack_motion *out, mlod_error *err);
/* The DOC chunk's glb bytes (*glb points into data after the CRC check;
 * the stream is stored raw). */
mlod_result mlod_pack_doc(const mlod_pack *p, const void *data, size_t size, const void **glb, size_t *glb_size,
                          mlod_error *err);

/* The DOC chunk's glb bytes, copied out of the chunk (its entropy stage
 * undone): glb lives in block; release with mlod_pack_doc_free.
 * mlod_pack_doc, which points into data, fails with MLOD_ERR_INVALID_ARG
 * for a DOC chunk with an entropy stage. */
typedef struct mlod_pack_doc_bytes {
	const uint8_t *glb;
	size_t size;
	void *block;
} mlod_pack_doc_bytes;
mlod_result mlod_pack_decode_doc(const mlod_pack *p, const void *data, size_t size, mlod_pack_doc_bytes *out,
                                 mlod_error *err);
void mlod_pack_doc_free(mlod_pack_doc_bytes *x);

/* Decodes every chunk of the pack in TOC order (data: the whole file) and
 * releases it: MLOD_OK when all decode, else the first failure, whose
 * message names the chunk; INFO's joint, skin and instance counts must be
 * SKELETON's and each MESH level's parts (MLOD_ERR_PARSE naming INFO;
 * mlod_pack_decode_info checks its level counts against the TOC and its
 * first_drawable exactly). mlod-pack --info runs it before listing, -x before unpacking. */
mlod_result mlod_pack_check(const mlod_pack *p, const void *data, size_t size, mlod_error *err);
/* The zero padding before each chunk, which no CRC covers (data: the
 * whole file, or a prefix: the bytes it holds): MLOD_ERR_PARSE naming the
 * chunk after a byte that is not zero, or bytes after the pack's end (the
 * header's file size). mlod_pack_check runs it first; mlod-pack -x too. */
mlod_result mlod_pack_check_padding(const mlod_pack *p, const void *data, size_t size, mlod_error *err);

void mlod_pack_info_free(mlod_pack_info *x);
void mlod_pack_skeleton_free(mlod_pack_skeleton *x);
void mlod_pack_skel_level_free(mlod_pack_skel_level *x);
void mlod_pack_mesh_free(mlod_pack_mesh *x);
void mlod_pack_motion_free(mlod_pack_motion *x);

/* The index of the chunk of this type, layer, level and item, or -1. */
int mlod_pack_find(const mlod_pack *p, uint32_t type, unsigned level, unsigned item);

/* "INFO", "SKEL", "MESH", "ANIM", "DOC" (a chunk type's fourcc, without
 * the trailing space; "unknown" for others); "none", "meshopt", "draco";
 * "none", "skeleton", "mesh", "motion". mlod_pack_type_name was added with
 * the reader: the comment named it, no declaration did. */
const char *mlod_pack_type_name(uint32_t type);
const char *mlod_pack_codec_name(unsigned codec);
const char *mlod_pack_entropy_name(unsigned entropy); /* "none", "zstd", "zstd-prefix" */
const char *mlod_pack_layer_name(unsigned layer);

#ifdef __cplusplus
}
#endif

#endif /* MLOD_PACK_H */
