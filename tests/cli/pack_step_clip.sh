# A clip whose samplers are STEP (the tubeman's walk, every sampler set to
# STEP) gets real reduced levels within their bounds. Its key times were
# stored as ticks within a tolerance: a STEP key read back a hair late
# gives the key before at the key's own time, so every level measured
# above its bound and levels 0 to 2 became the clip as read (error 0,
# every key: 120,360 raw bytes each).
node "$ROOT/tests/glb-edit.mjs" "$ROOT/samples/tubeman.glb" step.glb \
	'for (const a of j.animations) for (const s of a.samplers) s.interpolation = "STEP";' || exit 1
"$BIN/mlod-pack" -o step.mlod step.glb || exit 1
"$BIN/mlod-pack" --json --info step.mlod > info.json || exit 1
node -e '
const j = JSON.parse(require("fs").readFileSync("info.json"));
const anim = j.chunks.filter(c => c.type === "ANIM").sort((a, b) => a.level - b.level);
const bound = [0.05, 0.2, 1, 3];
if (anim.length !== 4) throw new Error(anim.length + " motion levels");
for (const c of anim) {
	if (!(c.error_percent <= bound[c.level])) throw new Error("level " + c.level + ": " + c.error_percent + "% over " + bound[c.level]);
	if (c.level > 0 && !(c.raw < anim[c.level - 1].raw)) throw new Error("level " + c.level + " not smaller than level " + (c.level - 1));
	if (c.level > 0 && !(c.error_percent > 0)) throw new Error("level " + c.level + ": error 0, the clip as read");
}' || exit 1
# mlod-motion --precision full piped into mlod-pack gives the pack
# mlod-pack makes itself, byte for byte, as for LINEAR clips (README):
# the same levels, so the same bytes. The glb keeps the input's name (the
# character's name comes from it).
mkdir piped || exit 1
"$BIN/mlod-motion" --precision full -o piped/step.glb step.glb || exit 1
(cd piped && "$BIN/mlod-pack" -o ../piped.mlod step.glb) || exit 1
cmp step.mlod piped.mlod || { echo "piped --precision full pack differs from the direct one"; exit 1; }
