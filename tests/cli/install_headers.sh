# make install puts the headers in one folder of their own,
# PREFIX/include/mlod (the parts' folders model/ to rt/ went straight into
# PREFIX/include, where other packages' io/ or mesh/ would clash; a
# new-user probe), with every header mlod.h includes where it includes it
# from, and pkg-config files: a program including mlod.h and mlod_rt.h
# compiles with `pkg-config --cflags mlod`, and a runtime program linked
# with `pkg-config --libs mlodrt` alone opens a pack. make uninstall
# removes every file install made. The runtime's headers also compile
# under an engine's stricter warnings.
set -e
make -s -C "$ROOT" install DESTDIR="$PWD/inst" PREFIX=/usr > /dev/null
for d in io mesh model rt; do test ! -e "inst/usr/include/$d"; done
test -f inst/usr/lib/libmlod.a && test -f inst/usr/lib/libmlodrt.a
pc() { PKG_CONFIG_SYSROOT_DIR="$PWD/inst" PKG_CONFIG_PATH="$PWD/inst/usr/lib/pkgconfig" pkg-config "$@"; }
printf '#include <mlod.h>\n#include <mlod_rt.h>\nint main(void) { return mlod_rt_palette_size(0) != 0; }\n' > t.c
cc -std=c11 -Wall -Wextra -Wpedantic -Werror $(pc --cflags mlod) -c t.c -o t.o
cc t.o $(pc --libs mlod) -o t
./t
cat > rt.c <<'C'
#include <stdio.h>
#include <mlod_rt.h>
int main(int argc, char **argv)
{
	mlod_rt_ctx *ctx = NULL;
	mlod_error e = {0};
	if (argc < 2 || mlod_rt_open_path(argv[1], NULL, &ctx, &e) != MLOD_OK) {
		fprintf(stderr, "%s\n", e.message);
		return 1;
	}
	/* names, hierarchy and a bound through the installed header */
	mlod_rt_character ch;
	uint32_t clip = 0, joint = 0, id = 0;
	mlod_rt_scratch *s = mlod_rt_scratch_create(ctx);
	float lo[3], hi[3];
	if (!s || mlod_rt_character_get(ctx, &ch, &e) || mlod_rt_clip_find(ctx, mlod_rt_clip_name(ctx, 0), &clip, &e) ||
	    mlod_rt_joint_find(ctx, "Hips", &joint, &e) || mlod_rt_joint_parent(ctx, joint) != -1 ||
	    mlod_rt_instance_create(ctx, clip, 0, 0, &id, &e) || mlod_rt_bounds(ctx, s, id, lo, hi, &e) || lo[1] > hi[1]) {
		fprintf(stderr, "%s\n", e.message);
		return 1;
	}
	printf("%s: clip %s, joint %s, height %.1f\n", ch.name, mlod_rt_clip_name(ctx, clip), mlod_rt_joint_name(ctx, joint),
	       (double)(hi[1] - lo[1]));
	mlod_rt_scratch_destroy(ctx, s);
	mlod_rt_close(ctx);
	return 0;
}
C
cc -std=c11 -Wall -Wextra -Wpedantic -Werror $(pc --cflags mlodrt) rt.c $(pc --libs mlodrt) -o rt
# an engine's stricter warnings: the runtime's public headers compile
# clean under -Wconversion -Wdouble-promotion -Werror (mlod_pack.h's inline
# mlod_pack_rotq_key warned under both)
printf '#include <mlod_rt.h>\n#include <mlod_pack.h>\nint main(void) { return 0; }\n' > strict.c
cc -std=c11 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wdouble-promotion -Werror $(pc --cflags mlodrt) \
	-c strict.c -o strict.o
"$BIN/mlod-pack" "$ROOT/samples/tubeman.glb" -o t.mlod
./rt t.mlod > rt.out
grep -q '^tubeman: clip walk, joint Hips' rt.out || { cat rt.out >&2; exit 1; }
make -s -C "$ROOT" uninstall DESTDIR="$PWD/inst" PREFIX=/usr > /dev/null
left=$(find inst -type f -o -type l)
[ -z "$left" ] || { echo "left after uninstall: $left" >&2; exit 1; }
