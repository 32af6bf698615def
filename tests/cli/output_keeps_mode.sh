# -o onto an existing file keeps its permission bits and (where the user
# may give them) its owner and group: a private file stays private. A new
# file gets 0666 less the umask. A hard link keeps the old contents: the
# file is replaced by a rename, as sed -i does (mlod-label(1) OPTIONS).
set -e
umask 022
printf 'old' > private.glb
chmod 0640 private.glb
ln private.glb link.glb
if [ "$(id -u)" = 0 ]; then chown 4321:1234 private.glb; fi
"$BIN/mlod-label" -o private.glb "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(head -c 4 private.glb)" = glTF
test "$(stat -c %a private.glb)" = 640
if [ "$(id -u)" = 0 ]; then test "$(stat -c %u:%g private.glb)" = 4321:1234; fi
test "$(cat link.glb)" = old
# Through a symbolic link: the file it names keeps its bits.
printf 'old' > target.glb
chmod 0600 target.glb
ln -s target.glb sym.glb
"$BIN/mlod-label" -o sym.glb "$ROOT/samples/cmu_12_01_walk.bvh"
test -L sym.glb
test "$(stat -c %a target.glb)" = 600
"$BIN/mlod-label" -o new.glb "$ROOT/samples/cmu_12_01_walk.bvh"
test "$(stat -c %a new.glb)" = 644
