# mlod: multi-layer level of detail for skinned characters.
#
#   make                  library, runtime and tools (build/release/bin)
#   make test             unit + CLI + validator tests, then the unit tests under ASan/UBSan
#   make test-extended    also uses ../shared/data when it is present
#   make bench            benchmarks against the peers (bench/RESULTS.md)
#   make fuzz             libFuzzer on the pack reader (every codec, Draco
#                         included) and one frame of the runtime at every
#                         level (clang; not in make test)
#   make fuzz-unpack      libFuzzer on mlod-pack -x: pack to glTF to glb
#   make fuzz-io          libFuzzer on BVH, glb/glTF and the stage record
#                         (FUZZ_TARGET=bvh|gltf|record, FUZZ_TIME s each)
#   make demo             the main job on the bundled sample
#   make install          PREFIX=/usr/local DESTDIR= MANDIR=$(PREFIX)/share/man
#                         (headers in $(PREFIX)/include/mlod; pkg-config mlod, mlodrt)
#   make uninstall        the same variables
#   make config=debug|release|sanitize
#
# Link order matters: -ltinygltf must come before -ldraco, which exports an
# older copy of tinygltf's symbols (scripts/check-deps probes it so).

config ?= release
PREFIX ?= /usr/local
MANDIR ?= $(PREFIX)/share/man
DESTDIR ?=

CC ?= cc
CXX ?= c++
WARN := -Wall -Wextra -Wpedantic
# The bake side sees lib/ (parts are included as "part/mlod_part.h") and the
# core; the runtime (lib/rt) sees only the core and its own folder.
CPPFLAGS += -Ilib -Ilib/core
RT_CPPFLAGS := -Ilib/core -Ilib/rt
CFLAGS_release := -O2 -g
CFLAGS_debug := -O0 -g3
CFLAGS_sanitize := -O1 -g -fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer -fno-sanitize-recover=undefined,float-cast-overflow
CFLAGS += -std=c11 -pthread $(WARN) $(CFLAGS_$(config))
# (MLOD_DRACO: set below; the unit tests see it to know the runtime they link)
CXXFLAGS += -std=c++14 -pthread -Wall -Wextra $(CFLAGS_$(config))
LDFLAGS_sanitize := -fsanitize=address,undefined,float-cast-overflow
LDFLAGS += -pthread $(LDFLAGS_$(config))
# meshoptimizer's codecs (the pack writer's encoder, the runtime's decoder) and
# Draco's core mesh codec (lib/pack/draco.cpp); -ltinygltf before -ldraco;
# zstd (libzstd-dev), the pack's entropy stage (writer and reader).
LDLIBS := -ltinygltf -lmeshoptimizer -ldraco -lzstd -lstdc++ -lm

# MLOD_DRACO=1 (the default; libdraco-dev is in scripts/install-deps)
# builds the runtime's Draco decode, lib/rt/rt_draco.cpp, the one C++ file
# lib/rt may hold; MLOD_DRACO=0 gives a runtime that refuses Draco chunks
# as unsupported (built under build/$(config)-nodraco).
MLOD_DRACO ?= 1
CPPFLAGS += -DMLOD_DRACO=$(MLOD_DRACO)
ifeq ($(MLOD_DRACO),1)
B := build/$(config)
else
B := build/$(config)-nodraco
endif
BIN := $(B)/bin

LIB_PARTS := core model io measure skeleton mesh motion record pack
LIB_C := $(sort $(foreach p,$(LIB_PARTS),$(wildcard lib/$(p)/*.c)))
LIB_CXX := $(sort $(foreach p,$(LIB_PARTS),$(wildcard lib/$(p)/*.cpp)))
LIB_OBJ := $(LIB_C:%.c=$(B)/%.o) $(LIB_CXX:%.cpp=$(B)/%.o)
RT_C := $(sort $(wildcard lib/rt/*.c))
RT_OBJ := $(RT_C:%.c=$(B)/%.o)
# No C++ in lib/rt but the Draco shim.
RT_FOREIGN := $(filter-out lib/rt/rt_draco.cpp,$(wildcard lib/rt/*.cpp lib/rt/*.cc lib/rt/*.cxx lib/rt/*.C))
ifneq ($(RT_FOREIGN),)
$(error lib/rt is C only but for lib/rt/rt_draco.cpp: $(RT_FOREIGN))
endif
ifeq ($(MLOD_DRACO),1)
RT_OBJ += $(B)/lib/rt/rt_draco.o
endif
TOOL_NAMES := $(notdir $(basename $(sort $(wildcard tools/mlod-*.c))))
TOOL_COMMON_OBJ := $(B)/tools/common.o
TOOLS := $(TOOL_NAMES:%=$(BIN)/%)
UNIT_SRC := $(sort $(wildcard tests/unit/test_*.c))
UNIT := $(UNIT_SRC:tests/unit/%.c=$(B)/tests/%)
HELPERS := $(patsubst tests/helpers/%.c,$(B)/tests/helpers/%,$(wildcard tests/helpers/*.c))
BENCH := $(patsubst bench/%.c,$(B)/bench/%,$(wildcard bench/*.c))

# Keep object files that pattern chains would treat as intermediate.
.SECONDARY:

.PHONY: all unit rt-unit test test-extended bench demo install uninstall clean samples

all: $(B)/libmlod.a $(B)/libmlodrt.a $(TOOLS)

$(B)/libmlod.a: $(LIB_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# The runtime library: lib/rt plus the core, nothing from the bake side.
CORE_OBJ := $(patsubst %.c,$(B)/%.o,$(sort $(wildcard lib/core/*.c)))
$(B)/libmlodrt.a: $(RT_OBJ) $(CORE_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# The core and the runtime compile with only the core and lib/rt on the
# include path, so neither can include a bake-side header; C only.
$(B)/lib/core/%.o: lib/core/%.c
	@mkdir -p $(@D)
	$(CC) $(RT_CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

$(B)/lib/rt/%.o: lib/rt/%.c
	@mkdir -p $(@D)
	$(CC) $(RT_CPPFLAGS) -DMLOD_DRACO=$(MLOD_DRACO) $(CFLAGS) -MMD -MP -c $< -o $@

# The Draco shim: the runtime's include path, Draco's core decoder only.
$(B)/lib/rt/rt_draco.o: lib/rt/rt_draco.cpp
	@mkdir -p $(@D)
	$(CXX) $(RT_CPPFLAGS) $(CXXFLAGS) -MMD -MP -c $< -o $@

# Runtime test programs link libmlodrt.a alone: no tinygltf, no C++, no
# libmlod. A bake-side symbol in the runtime fails this link.
RT_TEST_SRC := $(sort $(wildcard tests/rt/*.c))
RT_TESTS := $(RT_TEST_SRC:tests/rt/%.c=$(B)/tests/rt/%)
RT_LDLIBS := -lmeshoptimizer -lzstd -lm
ifeq ($(MLOD_DRACO),1)
RT_LDLIBS := -lmeshoptimizer -ldraco -lzstd -lstdc++ -lm
endif
$(B)/tests/rt/%: tests/rt/%.c $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(RT_CPPFLAGS) -DMLOD_DRACO=$(MLOD_DRACO) $(CFLAGS) $(LDFLAGS) $^ $(RT_LDLIBS) -o $@

$(B)/%.o: %.c
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

# lib/mesh in the release build: its small fixed loops (a face's three
# corners, a quadric's ten entries, the two or three collapsed vertices)
# unrolled whole, which -O2 leaves as loops where that grows the code; the
# same arithmetic in the same order, so the same bits. Measured (bench/
# RESULTS.md, issue 13): the mesh chain 3.6-5.0% fewer instructions on
# tubeman, RobotExpressive and Ely, the outputs cmp-identical.
CFLAGS_mesh_release := -fpeel-loops
$(B)/lib/mesh/%.o: CFLAGS += $(CFLAGS_mesh_$(config))
# lib/measure the same (a triangle's three corners, a point's three
# coordinates): mlod-bgm's measuring on the 50k-triangle tubeman 8.3%
# fewer instructions, the outputs cmp-identical (bench/RESULTS.md).
CFLAGS_measure_release := -fpeel-loops
$(B)/lib/measure/%.o: CFLAGS += $(CFLAGS_measure_$(config))

$(B)/%.o: %.cpp
	@mkdir -p $(@D)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -MMD -MP -c $< -o $@

$(BIN)/%: $(B)/tools/%.o $(TOOL_COMMON_OBJ) $(B)/libmlod.a $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(B)/tests/%: $(B)/tests/unit/%.o $(B)/libmlod.a $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(B)/tests/helpers/%: $(B)/tests/helpers/%.o $(B)/libmlod.a $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@

$(B)/bench/%: $(B)/bench/%.o $(B)/libmlod.a $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(LDFLAGS) $^ $(LDLIBS) -o $@
# bench/crowd writes its picture with libpng (libpng-dev), linked there only.
$(B)/bench/crowd: LDLIBS += -lpng
# bench/pack_streams -z also measures deflate (zlib1g-dev) on each chunk.
$(B)/bench/pack_streams: LDLIBS += -lz

unit: $(UNIT) $(HELPERS) $(RT_TESTS)

# The runtime's tests alone (`make MLOD_DRACO=0 rt-unit`: the runtime built
# without its Draco decode, which `test` runs too).
rt-unit: $(RT_TESTS)

# The whole suite: unit, CLI and validator tests on the release build, then
# the unit tests again under AddressSanitizer and UBSan.
test: all unit $(B)/bench/crowd
	@$(MAKE) --no-print-directory config=sanitize unit
	@$(MAKE) --no-print-directory MLOD_DRACO=0 rt-unit
	@tests/run.sh --build $(B) --sanitize-build build/sanitize --nodraco-build build/$(config)-nodraco

test-extended: all unit $(B)/bench/crowd
	@$(MAKE) --no-print-directory config=sanitize unit
	@$(MAKE) --no-print-directory MLOD_DRACO=0 rt-unit
	@tests/run.sh --build $(B) --sanitize-build build/sanitize --nodraco-build build/$(config)-nodraco --extended

bench: all $(BENCH) $(HELPERS)
	@bench/run.sh $(B)

demo: all $(B)/bench/crowd
	@scripts/demo $(BIN) $(B)/bench/crowd

# Regenerates the procedural sample character.
samples: all $(HELPERS)
	@scripts/gen-sample $(B)

# The parts whose headers mlod.h includes (lib/PART/mlod_*.h).
PUBLIC_PARTS := model io measure skeleton mesh motion record pack rt

# Installed headers live in one folder of their own, $(PREFIX)/include/mlod
# (the parts' folders, model/ to rt/, would clash with other packages'
# in include/), which a program adds with -I: the pkg-config files
# mlod.pc (the bake library) and mlodrt.pc (the runtime) say so, with the
# libraries to link. mlod_rt.h and mlod_pack.h there only include
# rt/mlod_rt.h and rt/mlod_pack.h.
INCDIR := $(PREFIX)/include/mlod
MLOD_VERSION := $(shell sed -n 's/^\#define MLOD_VERSION "\(.*\)"/\1/p' lib/core/mlod_core.h)
PCDIR := $(PREFIX)/lib/pkgconfig
ifeq ($(MLOD_DRACO),1)
RT_LIBS := -lmlodrt -lmeshoptimizer -ldraco -lzstd -lstdc++ -lm
else
RT_LIBS := -lmlodrt -lmeshoptimizer -lzstd -lm
endif

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PCDIR) $(DESTDIR)$(INCDIR) $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(MANDIR)/man3 $(DESTDIR)$(MANDIR)/man5
	install -m 755 $(TOOLS) $(DESTDIR)$(PREFIX)/bin
	install -m 644 $(B)/libmlod.a $(B)/libmlodrt.a $(DESTDIR)$(PREFIX)/lib
	# the bake library's umbrella header and its part headers, in the
	# folders it includes them from (model/mlod_model.h, ..., rt/mlod_pack.h)
	install -m 644 lib/mlod.h lib/core/mlod_core.h $(DESTDIR)$(INCDIR)
	for p in $(PUBLIC_PARTS); do \
		install -d $(DESTDIR)$(INCDIR)/$$p && install -m 644 lib/$$p/mlod_*.h $(DESTDIR)$(INCDIR)/$$p || exit 1; \
	done
	# the runtime's headers by the names its man pages give
	for h in mlod_rt.h mlod_pack.h; do \
		printf '/* mlod: the runtime header rt/%s */\n#include "rt/%s"\n' $$h $$h > $(DESTDIR)$(INCDIR)/$$h || exit 1; \
	done
	printf 'prefix=%s\nincludedir=$${prefix}/include/mlod\nlibdir=$${prefix}/lib\n\nName: mlodrt\nDescription: mlod runtime: streams .mlod packs, picks levels, poses and skins crowds\nVersion: %s\nCflags: -I$${includedir}\nLibs: -L$${libdir} %s\n' \
		'$(PREFIX)' '$(MLOD_VERSION)' '$(RT_LIBS)' > $(DESTDIR)$(PCDIR)/mlodrt.pc
	printf 'prefix=%s\nincludedir=$${prefix}/include/mlod\nlibdir=$${prefix}/lib\n\nName: mlod\nDescription: mlod bake library: skeleton, mesh and motion levels of detail and the .mlod pack writer\nVersion: %s\nCflags: -I$${includedir}\nLibs: -L$${libdir} -lmlod -lmlodrt %s -pthread\n' \
		'$(PREFIX)' '$(MLOD_VERSION)' '$(LDLIBS)' > $(DESTDIR)$(PCDIR)/mlod.pc
	install -m 644 man/man1/*.1 $(DESTDIR)$(MANDIR)/man1
	if ls man/man3/*.3 >/dev/null 2>&1; then install -m 644 man/man3/*.3 $(DESTDIR)$(MANDIR)/man3; fi
	# a link per function a man3 page names (its NAME's .Nm lines), so that
	# man mlod_rt_update finds mlod_rt_instance(3)
	for p in man/man3/*.3; do \
		[ -f "$$p" ] || continue; b=$${p##*/}; \
		for n in $$(sed -n '/^\.Sh NAME/,/^\.Nd/s/^\.Nm \([A-Za-z0-9_]*\).*/\1/p' "$$p"); do \
			[ "$$n.3" = "$$b" ] || ln -sf "$$b" $(DESTDIR)$(MANDIR)/man3/$$n.3 || exit 1; \
		done; \
	done
	if ls man/man5/*.5 >/dev/null 2>&1; then install -m 644 man/man5/*.5 $(DESTDIR)$(MANDIR)/man5; fi

# Removes what install put there (the same PREFIX, DESTDIR and MANDIR).
uninstall:
	rm -f $(TOOL_NAMES:%=$(DESTDIR)$(PREFIX)/bin/%)
	rm -f $(DESTDIR)$(PREFIX)/lib/libmlod.a $(DESTDIR)$(PREFIX)/lib/libmlodrt.a $(DESTDIR)$(PCDIR)/mlod.pc $(DESTDIR)$(PCDIR)/mlodrt.pc
	rm -rf $(DESTDIR)$(INCDIR)
	for p in man/man1/*.1 man/man5/*.5; do rm -f $(DESTDIR)$(MANDIR)/$$(basename $$(dirname $$p))/$${p##*/}; done
	for p in man/man3/*.3; do \
		[ -f "$$p" ] || continue; rm -f $(DESTDIR)$(MANDIR)/man3/$${p##*/}; \
		for n in $$(sed -n '/^\.Sh NAME/,/^\.Nd/s/^\.Nm \([A-Za-z0-9_]*\).*/\1/p' "$$p"); do \
			rm -f $(DESTDIR)$(MANDIR)/man3/$$n.3; \
		done; \
	done

# build/deps (the OpenMesh headers scripts/install-deps unpacks) stays: the
# tests need them and only install-deps puts them back.
clean:
	rm -rf $(filter-out build/deps,$(wildcard build/*))

# --- Mesh layer (issue 4) ---------------------------------------------
# tests/openmesh/test_openmesh.cpp checks every mesh level of every sample
# with OpenMesh (headers from libopenmesh-dev, or unpacked into build/deps
# by scripts/install-deps; the library from libopenmesh1). It is part of
# `unit` for the release and debug builds, not under the sanitizers.
# (-Wno-maybe-uninitialized: a false positive inside OpenMesh's
# PropertyT::push_back.) bench/bench_mesh compares with meshoptimizer,
# linked there only.
OPENMESH_HDR := $(firstword $(wildcard /usr/include/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh build/deps/usr/include/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh))
OPENMESH_INC := $(patsubst %/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh,%,$(OPENMESH_HDR))
OPENMESH_LIB ?= -l:libOpenMeshCore.so.9.0
ifneq ($(config),sanitize)
unit: $(B)/tests/test_openmesh
endif
$(B)/tests/test_openmesh: tests/openmesh/test_openmesh.cpp lib/mlod.h $(B)/libmlod.a
	@mkdir -p $(@D)
	@if [ -z "$(OPENMESH_INC)" ]; then echo "OpenMesh headers are missing: run scripts/install-deps" >&2; exit 1; fi
	$(CXX) $(CPPFLAGS) -isystem $(OPENMESH_INC) $(CXXFLAGS) -Wno-maybe-uninitialized $< $(B)/libmlod.a $(OPENMESH_LIB) $(LDFLAGS) $(LDLIBS) -o $@
# ----------------------------------------------------------------------

# --- Pack reader fuzzing ----------------------------------------------
# make fuzz: libFuzzer on the pack reader and the runtime
# (tests/fuzz/fuzz_pack.c: every chunk decoded, then one frame evaluated
# at every level), built with clang (Debian: clang, libclang-rt-dev)
# under ASan and UBSan from the runtime's sources alone, with its Draco
# shim (clang++, -ldraco). Not part of `make test`. The corpus starts with
# the test character's packs (test_pack_reader --write-seed*) and the tiny
# tubeman packed by the release tools with each codec, draco included
# (tests/fuzz/seeds.sh, build/fuzz/seeds-pack), and grows in
# build/fuzz/corpus. FUZZ_TIME=seconds (default 60); FUZZ_ARGS passes more.
# make fuzz-unpack: the same seeds through mlod_pack_unpack and the glb
# writer (tests/fuzz/fuzz_unpack.c, what mlod-pack -x does), linked with
# the bake library as fuzz-io is; corpus build/fuzz/corpus-unpack.
# Both stop at an input slower than FUZZ_TIMEOUT s or past FUZZ_RSS_MB
# (crashes in build/fuzz/crash-pack, crash-unpack) and first replay the
# inputs of fixed findings (tests/fuzz/regress/pack, regress/unpack).
FUZZ_CC ?= clang
FUZZ_CXX ?= clang++
FUZZ_TIME ?= 60
FUZZ_TIMEOUT ?= 30
FUZZ_RSS_MB ?= 2048
FUZZ_ARGS ?=
FUZZ_IO_FLAGS := -g -O1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_IO_OBJ := $(LIB_C:%.c=build/fuzz/obj/%.o) $(LIB_CXX:%.cpp=build/fuzz/obj/%.o)
FUZZ_PACK_SEEDS := build/fuzz/corpus/seed.mlod build/fuzz/seeds-pack/tiny.draco.mlod
.PHONY: fuzz fuzz-unpack fuzz-pack-build
fuzz: build/fuzz/fuzz_pack $(FUZZ_PACK_SEEDS)
	@mkdir -p build/fuzz/crash-pack
	@if [ -d tests/fuzz/regress/pack ]; then echo "fuzz: replaying tests/fuzz/regress/pack"; \
		build/fuzz/fuzz_pack tests/fuzz/regress/pack/* > build/fuzz/regress-pack.log 2>&1 \
			|| { cat build/fuzz/regress-pack.log >&2; exit 1; }; fi
	build/fuzz/fuzz_pack -max_total_time=$(FUZZ_TIME) -timeout=$(FUZZ_TIMEOUT) -rss_limit_mb=$(FUZZ_RSS_MB) \
		-malloc_limit_mb=$(FUZZ_RSS_MB) -max_len=65536 -artifact_prefix=build/fuzz/crash-pack/ $(FUZZ_ARGS) \
		build/fuzz/corpus build/fuzz/seeds-pack
fuzz-unpack: build/fuzz/fuzz_unpack $(FUZZ_PACK_SEEDS)
	@mkdir -p build/fuzz/corpus-unpack build/fuzz/crash-unpack
	@if [ -d tests/fuzz/regress/unpack ]; then echo "fuzz-unpack: replaying tests/fuzz/regress/unpack"; \
		build/fuzz/fuzz_unpack tests/fuzz/regress/unpack/* > build/fuzz/regress-unpack.log 2>&1 \
			|| { cat build/fuzz/regress-unpack.log >&2; exit 1; }; fi
	build/fuzz/fuzz_unpack -max_total_time=$(FUZZ_TIME) -timeout=$(FUZZ_TIMEOUT) -rss_limit_mb=$(FUZZ_RSS_MB) \
		-malloc_limit_mb=$(FUZZ_RSS_MB) -max_len=65536 -artifact_prefix=build/fuzz/crash-unpack/ $(FUZZ_ARGS) \
		build/fuzz/corpus-unpack build/fuzz/corpus build/fuzz/seeds-pack
fuzz-pack-build: build/fuzz/fuzz_pack build/fuzz/fuzz_unpack $(FUZZ_PACK_SEEDS)
build/fuzz/corpus/seed.mlod: $(B)/tests/rt/test_pack_reader
	@mkdir -p $(@D)
	$(B)/tests/rt/test_pack_reader --write-seed build/fuzz/corpus/seed.mlod
	$(B)/tests/rt/test_pack_reader --write-seed-zstd build/fuzz/corpus/seed-zstd.mlod
	$(B)/tests/rt/test_pack_reader --write-seed-prefix build/fuzz/corpus/seed-prefix.mlod
build/fuzz/seeds-pack/tiny.draco.mlod: build/fuzz/seeds-record/tiny.staged.json
FUZZ_RT_OBJ := $(RT_C:%.c=build/fuzz/objd/%.o) build/fuzz/objd/lib/rt/rt_draco.o
build/fuzz/fuzz_pack: build/fuzz/objd/tests/fuzz/fuzz_pack.o $(FUZZ_RT_OBJ) $(patsubst %.c,build/fuzz/obj/%.o,$(sort $(wildcard lib/core/*.c)))
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ -lmeshoptimizer -ldraco -lzstd -lm -pthread -o $@
build/fuzz/fuzz_unpack: build/fuzz/objd/tests/fuzz/fuzz_unpack.o $(FUZZ_IO_OBJ) $(FUZZ_RT_OBJ)
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ $(LDLIBS) -pthread -o $@
build/fuzz/objd/tests/fuzz/fuzz_pack.o: tests/fuzz/fuzz_pack.c
	@mkdir -p $(@D)
	@command -v $(FUZZ_CC) >/dev/null 2>&1 || { echo "make fuzz needs clang with libFuzzer (Debian: clang libclang-rt-dev)" >&2; exit 1; }
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(RT_CPPFLAGS) -DMLOD_DRACO=1 -MMD -MP -c $< -o $@
build/fuzz/objd/tests/fuzz/fuzz_unpack.o: tests/fuzz/fuzz_unpack.c
	@mkdir -p $(@D)
	@command -v $(FUZZ_CC) >/dev/null 2>&1 || { echo "make fuzz-unpack needs clang with libFuzzer (Debian: clang libclang-rt-dev)" >&2; exit 1; }
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(CPPFLAGS) $(RT_CPPFLAGS) -MMD -MP -c $< -o $@
build/fuzz/objd/lib/rt/%.o: lib/rt/%.c
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(RT_CPPFLAGS) -DMLOD_DRACO=1 -MMD -MP -c $< -o $@
build/fuzz/objd/lib/rt/rt_draco.o: lib/rt/rt_draco.cpp
	@mkdir -p $(@D)
	$(FUZZ_CXX) -std=c++14 -pthread -Wall -Wextra $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(RT_CPPFLAGS) -DMLOD_DRACO=1 -MMD -MP -c $< -o $@
# ----------------------------------------------------------------------

# --- Bake-side input fuzzing ------------------------------------------
# make fuzz-io: libFuzzer on what the tools read, built with clang and
# clang++ under ASan and UBSan from the whole bake library. Targets
# (FUZZ_TARGET, default all three in turn, FUZZ_TIME seconds each):
#   bvh     tests/fuzz/fuzz_io.c on BVH seeds: mlod_load, then every record read
#   gltf    the same binary on glb and glTF seeds (the samples, each stage's output)
#   record  tests/fuzz/fuzz_record.c: extras.mlod of a staged glb (JSON)
# tests/fuzz/seeds.sh writes the seeds (build/fuzz/seeds-*) from the
# samples through the release tools; corpora grow in build/fuzz/corpus-*,
# crashes land in build/fuzz/crash-*. A slow input (FUZZ_TIMEOUT s) or one
# past FUZZ_RSS_MB is a finding. The inputs of fixed findings
# (tests/fuzz/regress/TARGET) are replayed first; a crash there stops.
FUZZ_TARGET ?= bvh gltf record
.PHONY: fuzz-io fuzz-io-build
fuzz-io: fuzz-io-build
	@for t in $(FUZZ_TARGET); do case $$t in bvh|gltf|record) ;; *) echo "FUZZ_TARGET: bvh, gltf or record, not $$t" >&2; exit 1;; esac; done
	@set -e; for t in $(FUZZ_TARGET); do \
		mkdir -p build/fuzz/corpus-$$t build/fuzz/crash-$$t; \
		bin=build/fuzz/fuzz_io; max=2097152; [ $$t = record ] && bin=build/fuzz/fuzz_record; [ $$t = gltf ] || max=65536; \
		if [ -d tests/fuzz/regress/$$t ]; then \
			echo "fuzz-io: $$t: replaying tests/fuzz/regress/$$t"; \
			MLOD_FUZZ_BASE=build/fuzz/stage/tiny.staged.glb $$bin tests/fuzz/regress/$$t/* > build/fuzz/regress-$$t.log 2>&1 \
				|| { cat build/fuzz/regress-$$t.log >&2; exit 1; }; \
		fi; \
		echo "fuzz-io: $$t for $(FUZZ_TIME) s"; \
		MLOD_FUZZ_BASE=build/fuzz/stage/tiny.staged.glb $$bin -max_total_time=$(FUZZ_TIME) -timeout=$(FUZZ_TIMEOUT) \
			-rss_limit_mb=$(FUZZ_RSS_MB) -malloc_limit_mb=$(FUZZ_RSS_MB) -max_len=$$max -dict=tests/fuzz/$$t.dict \
			-artifact_prefix=build/fuzz/crash-$$t/ $(FUZZ_ARGS) build/fuzz/corpus-$$t build/fuzz/seeds-$$t; \
	done
fuzz-io-build: build/fuzz/fuzz_io build/fuzz/fuzz_record build/fuzz/seeds-record/tiny.staged.json
build/fuzz/seeds-record/tiny.staged.json: tests/fuzz/seeds.sh $(TOOLS) $(B)/tests/helpers/gen_tubeman build/fuzz/record_seed
	tests/fuzz/seeds.sh $(BIN) $(B)/tests/helpers build/fuzz build/fuzz/record_seed
build/fuzz/record_seed: tests/fuzz/record_seed.c $(B)/libmlod.a $(B)/libmlodrt.a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $< $(B)/libmlod.a $(B)/libmlodrt.a $(LDFLAGS) $(LDLIBS) -o $@
build/fuzz/fuzz_io build/fuzz/fuzz_record: build/fuzz/%: build/fuzz/obj/tests/fuzz/%.o $(FUZZ_IO_OBJ) $(RT_C:%.c=build/fuzz/obj/%.o)
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined $^ $(LDLIBS) -pthread -o $@
build/fuzz/obj/tests/fuzz/%.o: tests/fuzz/%.c
	@mkdir -p $(@D)
	@command -v $(FUZZ_CC) >/dev/null 2>&1 || { echo "make fuzz-io needs clang with libFuzzer (Debian: clang libclang-rt-dev)" >&2; exit 1; }
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(CPPFLAGS) -MMD -MP -c $< -o $@
build/fuzz/obj/lib/core/%.o: lib/core/%.c
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(RT_CPPFLAGS) -MMD -MP -c $< -o $@
build/fuzz/obj/lib/rt/%.o: lib/rt/%.c
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(RT_CPPFLAGS) -MMD -MP -c $< -o $@
build/fuzz/obj/%.o: %.c
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -pthread $(WARN) $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(CPPFLAGS) -MMD -MP -c $< -o $@
build/fuzz/obj/%.o: %.cpp
	@mkdir -p $(@D)
	$(FUZZ_CXX) -std=c++14 -pthread -Wall -Wextra $(FUZZ_IO_FLAGS) -fsanitize=fuzzer-no-link $(CPPFLAGS) -MMD -MP -c $< -o $@
# ----------------------------------------------------------------------

-include $(shell find build -name '*.d' 2>/dev/null)
