# make install puts every header mlod.h includes where it includes it
# from: a program including mlod.h and mlod_rt.h compiles against the
# installed tree alone (a new-user probe found model/mlod_model.h missing).
set -e
make -s -C "$ROOT" install DESTDIR="$PWD/inst" PREFIX=/usr > /dev/null
printf '#include <mlod.h>\n#include <mlod_rt.h>\nint main(void) { return mlod_rt_palette_size(0) != 0; }\n' > t.c
cc -std=c11 -Wall -Wextra -Wpedantic -Werror -I inst/usr/include -c t.c -o t.o
test -f inst/usr/lib/libmlod.a && test -f inst/usr/lib/libmlodrt.a
