# The tools' default -j (mlod_thread_count) is the processors the process
# may run on: its CPU affinity (taskset), not every processor online (a run
# bound to one CPU started 2 threads on this 2-core machine).
set -e
cat > t.c <<'C'
#include <stdio.h>
#include "mlod_core.h"
int main(void) { printf("%d\n", mlod_thread_count()); return 0; }
C
cc -std=c11 -I "$ROOT/lib/core" t.c "$BIN/../libmlod.a" -pthread -o t
n=$(nproc)
test "$(./t)" = "$(( n > 64 ? 64 : n ))"
one='import os, sys; os.sched_setaffinity(0, {min(os.sched_getaffinity(0))}); os.execv(sys.argv[1], sys.argv[1:])'
test "$(python3 -c "$one" ./t)" = 1
