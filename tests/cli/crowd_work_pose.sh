# bench/crowd --work pose measures the update, motion sampling, pose and
# palette of each instance, without skinning (a caller that skins on the
# GPU; the paper's Figure 15): the header names the work and the rate
# column is palette matrices; the levels chosen are the same as with
# --work skin for the same walk (selection does not depend on the work),
# row by row.
set -eu
crowd=$BIN/../bench/crowd
"$BIN/mlod-pack" -o t.mlod "$ROOT/samples/tubeman.glb"
for w in skin pose; do
	"$crowd" -n 1,40 -s 0.2 --max-wall 60 --mode skeleton,alpha,pixels --no-skin-bench --work $w t.mlod > $w.out
done
grep -q '; work: pose (motion sampling, pose and palette; no skinning); modes: full' pose.out ||
	{ echo "no pose work on the header line:"; cat pose.out; exit 1; } >&2
grep -q '; work: skin (motion sampling, pose and skinning); modes: full' skin.out ||
	{ echo "no skin work on the header line:"; cat skin.out; exit 1; } >&2
grep -q '^ *N mode *ms/frame *speedup *Mpal/s' pose.out || { echo "no Mpal/s column:"; cat pose.out; exit 1; } >&2
# the rows: mode and the instances per level (the fields after the rate,
# up to the resident bytes)
rows() { awk '{ m = $2 == "full" ? "full" : $1; if (m !~ /^(full|alpha|pixels|skeleton)$/) next
	s = m; for (i = 5; i <= NF - 2; i++) s = s " " $i; print s }' "$1"; }
rows skin.out > skin.rows
rows pose.out > pose.rows
[ "$(wc -l < skin.rows)" -eq 8 ] || { echo "expected 8 rows:"; cat skin.rows; exit 1; } >&2
cmp -s skin.rows pose.rows || { echo "levels differ between --work skin and pose:"; diff skin.rows pose.rows; exit 1; } >&2
# the skeleton rows at 40 use a coarser skeleton level for some instances
grep '^skeleton' pose.rows | tail -1 | grep -qv '^skeleton 40 0 0 |' ||
	{ echo "the skeleton mode kept every instance at skeleton level 0:"; cat pose.rows; exit 1; } >&2
