# fsdem.h build: tests, valgrind, sanitizers, examples, demo, validation, benchmarks.
# Everything is built into build/. `make help` lists the targets.

CC      ?= cc
CXX     ?= c++
WARN    := -Wall -Wextra -Wpedantic
CFLAGS  ?= -O2 -g
STD     := -std=c99
LDLIBS  := -lm
BUILD   := build
# reference data of the validation cases, shipped in the repository (validation/data/README.md)
VALIDATION_DATA ?= validation/data

CHECK_CFLAGS = $(shell pkg-config --cflags check 2>/dev/null)
CHECK_LIBS   = $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lrt -lpthread -lm)

# every tests/test_<module>.c is a suite registered in tests/check_main.c
TEST_SRC   := $(sort $(wildcard tests/test_*.c)) tests/check_main.c tests/fsdem_impl.c
EXAMPLES   := $(patsubst examples/%.c,$(BUILD)/examples/%,$(wildcard examples/*.c))
VALIDATION := $(patsubst validation/%/main.c,%,$(wildcard validation/*/main.c))
BENCHES    := $(patsubst bench/%/main.c,%,$(wildcard bench/*/main.c))

.PHONY: all help test check-deps gnuplot-deps compile-checks map-check determinism valgrind sanitize examples demo bench install clean

all: $(BUILD)/check_fsdem examples

help:
	@echo "make fsdem.h    write the single header fsdem.h from src/ (src/README.md)"
	@echo "make test       Check suite (installs Check with apt-get when missing and run as root)"
	@echo "make test-float the Check suite with fsdem_real = float (-DFSDEM_USE_FLOAT)"
	@echo "make determinism  the same results from gcc and clang at -O0/-O2/-march=native/no SIMD"
	@echo "make valgrind   the suite under Valgrind (no errors, no leaks), its heavy tests sized down"
	@echo "                 (FSDEM_TEST_LIGHT=1, tests/fsdem_tests.h)"
	@echo "make test-omp   the suite built with OpenMP, on OMP_THREADS (2) threads"
	@echo "make tsan       ThreadSanitizer on the threaded solvers at 2 and 4 threads (clang, libomp-dev)"
	@echo "make sanitize   the suite with AddressSanitizer and UndefinedBehaviorSanitizer"
	@echo "make demo       the headline: water breaking through a pile of cylinders, PNG frames and ParaView"
	@echo "                 series in build/demo/ (about a minute)"
	@echo "make examples   all examples"
	@echo "make validate   the default tier of validation (within 20 min with -j2): every case at a resolution"
	@echo "                 that fits; everything in build/validation/ (REPORT.md)"
	@echo "make validate-publish [TIER=full]  the last run's records into validation/report-<tier>/ and"
	@echo "                 validation/REPORT-<tier>.md, to commit"
	@echo "                 (installs gnuplot-nox with apt-get when missing and run as root)"
	@echo "make validate-full  the full tier (the seeds' resolutions, fine runs: hours): build/validation-full/"
	@echo "                 REPORT.md; CASES=\"a b\" runs some cases (either tier)"
	@echo "make validate-status  which cases of the committed reports are stale (their code changed since)"
	@echo "make validate-report  render validation/REPORT-default.md and REPORT-full.md again from their records"
	@echo "make bench      throughput benchmarks (BENCH lines); BENCH_FLAGS=-march=native for this CPU"
	@echo "make install    fsdem.h, pkg-config file, CMake package to PREFIX (/usr/local); DESTDIR stages"
	@echo "make install-check  install to a temporary prefix, build via pkg-config and CMake, run"

$(BUILD):
	@mkdir -p $(BUILD)/examples $(BUILD)/validation $(BUILD)/bench

# Check is the one test dependency. Install it when we can, otherwise say exactly how.
check-deps:
	@if ! pkg-config --exists check 2>/dev/null; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing Check: apt-get install -y check pkg-config"; \
	    (apt-get install -y check pkg-config >/dev/null 2>&1 || (apt-get update >/dev/null && apt-get install -y check pkg-config >/dev/null)) \
	      || { echo "could not install Check; run: sudo apt-get install -y check pkg-config"; exit 1; }; \
	  else echo "Check is missing; run: sudo apt-get install -y check pkg-config"; exit 1; fi; \
	fi

$(BUILD)/check_fsdem: $(TEST_SRC) tests/fsdem_tests.h fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) $(CFLAGS) $(CHECK_CFLAGS) -I. $(TEST_SRC) -o $@ $(CHECK_LIBS) $(LDLIBS)

# The header compiles warning-free as C99 with gcc and clang (double and float, SIMD lanes of 16 bytes
# (SSE2), 64 (AVX-512) and one real (FSDEM_NO_SIMD)), and as C++ with g++ and clang++.
COMPILE_VARIANTS := "" "-DFSDEM_USE_FLOAT" "-mavx512f" "-DFSDEM_NO_SIMD"
compile-checks: | $(BUILD)
	@for c in gcc clang; do if command -v $$c >/dev/null; then for v in $(COMPILE_VARIANTS); do \
	  $$c $(STD) $(WARN) -O2 -Werror $$v -c tests/fsdem_impl.c -I. -o $(BUILD)/impl_check.o || exit 1; done; fi; done
	@for c in $(CXX) clang++; do if command -v $$c >/dev/null; then \
	  $$c $(WARN) -O2 -Werror -c tests/compile_cpp.cpp -I. -o $(BUILD)/compile_cpp.o || exit 1; \
	  $$c $(WARN) -O2 -Werror -mavx512f -c tests/compile_cpp.cpp -I. -o $(BUILD)/compile_cpp.o || exit 1; fi; done
	@$(CC) $(STD) -O0 -c tests/fsdem_impl.c -I. -o $(BUILD)/impl_double.o && $(CC) $(STD) -O0 -c tests/link_float_user.c -I. \
	  -o $(BUILD)/link_float_user.o
	@if $(CC) $(BUILD)/link_float_user.o $(BUILD)/impl_double.o -o $(BUILD)/link_mixed $(LDLIBS) 2>/dev/null; then \
	  echo "compile checks: a float translation unit linked against a double implementation"; exit 1; fi
	@echo "compile checks: gcc and clang (C99: double, float, AVX-512 lanes, no SIMD), $(CXX) and clang++: warning-free;" \
	  "float and double objects refuse to link together"

# fsdem.h is generated from src/ (src/README.md) and committed. `make fsdem.h` writes it; no other
# target does, so `make test` checks the committed header against src/ instead of rewriting it.
ifneq ($(filter fsdem.h,$(MAKECMDGOALS)),)
.PHONY: fsdem.h
fsdem.h:
	sh src/pack.sh fsdem.h
endif

# The map of fsdem.h (its >>tag banners) is exact, the header is what src/ packs into, and the float
# build's symbol list complete.
map-check:
	@sh tests/map_check.sh fsdem.h

test: map-check compile-checks $(BUILD)/check_fsdem
	$(BUILD)/check_fsdem

# The same results bit for bit from gcc and clang at -O0, -O2, -O2 -march=native and without SIMD:
# tests/determinism.c prints a hash of each solver's saved state, pinned in tests/determinism.expected
# (regenerate it, with the reason in the commit, when a change of the numerics is intended).
DETERMINISM_FLAGS := "-O0" "-O2" "-O2 -march=native" "-O2 -DFSDEM_NO_SIMD"
# ... and the same hashes from an OpenMP build (-fopenmp) at each of these thread counts (>>doc THREADS)
DETERMINISM_THREADS := 1 2 3 4
# ... and, with grains so small that every scene takes every threaded path (the dot products' blocks
# change, so these hashes are compared with the same build without OpenMP, not with the pins)
DETERMINISM_GRAIN := -DFSDEM__DEM_CHUNK=64 -DFSDEM__DOT_BLOCK=256 -DFSDEM__SWE_BAND_ROWS=2 -DFSDEM__TEAM_ITEMS=16
determinism: | $(BUILD)
	@for c in gcc clang; do if command -v $$c >/dev/null; then for f in $(DETERMINISM_FLAGS); do \
	  $$c $(STD) $(WARN) $$f -I. tests/determinism.c -o $(BUILD)/determinism $(LDLIBS) || exit 1; \
	  $(BUILD)/determinism > $(BUILD)/determinism.out || exit 1; \
	  if ! diff -q tests/determinism.expected $(BUILD)/determinism.out >/dev/null; then \
	    echo "determinism: $$c $$f gives other results:"; diff tests/determinism.expected $(BUILD)/determinism.out; exit 1; fi; \
	done; fi; done
	@for c in gcc clang; do if command -v $$c >/dev/null; then \
	  $$c $(STD) $(WARN) -O2 -fopenmp -I. tests/determinism.c -o $(BUILD)/determinism_omp $(LDLIBS) || exit 1; \
	  for t in $(DETERMINISM_THREADS); do OMP_NUM_THREADS=$$t $(BUILD)/determinism_omp > $(BUILD)/determinism.out || exit 1; \
	    if ! diff -q tests/determinism.expected $(BUILD)/determinism.out >/dev/null; then \
	      echo "determinism: $$c -fopenmp at $$t threads gives other results:"; diff tests/determinism.expected $(BUILD)/determinism.out; exit 1; fi; \
	done; fi; done
	@$(CC) $(STD) $(WARN) -O2 $(DETERMINISM_GRAIN) -I. tests/determinism.c -o $(BUILD)/determinism_grain $(LDLIBS) && \
	  $(BUILD)/determinism_grain > $(BUILD)/determinism_grain.out && \
	  $(CC) $(STD) $(WARN) -O2 -fopenmp $(DETERMINISM_GRAIN) -I. tests/determinism.c -o $(BUILD)/determinism_grain_omp $(LDLIBS) || exit 1; \
	for t in $(DETERMINISM_THREADS); do OMP_NUM_THREADS=$$t $(BUILD)/determinism_grain_omp > $(BUILD)/determinism.out || exit 1; \
	  diff -q $(BUILD)/determinism_grain.out $(BUILD)/determinism.out >/dev/null || { \
	    echo "determinism: with every loop threaded ($(DETERMINISM_GRAIN)), $$t threads differ from one:"; \
	    diff $(BUILD)/determinism_grain.out $(BUILD)/determinism.out; exit 1; }; done
	@echo "determinism: gcc and clang at $(DETERMINISM_FLAGS), and with OpenMP at $(DETERMINISM_THREADS) threads:" \
	  "every solver's state hash as pinned; with every threaded loop taken ($(DETERMINISM_GRAIN)), the same" \
	  "hashes at every thread count as without OpenMP"

# The same suite with fsdem_real = float; its tolerances follow the precision (tests/fsdem_tests.h).
.PHONY: test-float
$(BUILD)/check_fsdem_float: $(TEST_SRC) tests/fsdem_tests.h fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) $(CFLAGS) -DFSDEM_USE_FLOAT $(CHECK_CFLAGS) -I. $(TEST_SRC) -o $@ $(CHECK_LIBS) $(LDLIBS)

test-float: $(BUILD)/check_fsdem_float
	$(BUILD)/check_fsdem_float

# The Check suite built with OpenMP and run on OMP_THREADS threads (default 2): the threaded paths
# meet the same analytical checks.
OMP_THREADS ?= 2
.PHONY: test-omp tsan
$(BUILD)/check_fsdem_omp: $(TEST_SRC) tests/fsdem_tests.h fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) $(CFLAGS) -fopenmp $(CHECK_CFLAGS) -I. $(TEST_SRC) -o $@ $(CHECK_LIBS) $(LDLIBS)

test-omp: $(BUILD)/check_fsdem_omp
	OMP_NUM_THREADS=$(OMP_THREADS) $(BUILD)/check_fsdem_omp

# ThreadSanitizer on the threaded code (clang, LLVM's OpenMP runtime with its Archer tool, so the
# runtime's own synchronisation is understood): every determinism scene, and the suites of the
# threaded solvers, at 2 and 4 threads. Needs libomp-dev (installed like Check when run as root).
TSAN_SUITES := swe linalg dem dem_contact
tsan: | $(BUILD) check-deps
	@if ! ls /usr/lib/llvm-*/lib/libarcher.so >/dev/null 2>&1 && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing LLVM's OpenMP runtime: apt-get install -y libomp-dev"; apt-get install -y libomp-dev >/dev/null 2>&1; fi
	clang $(STD) $(WARN) -O1 -g -fopenmp -fsanitize=thread -I. tests/determinism.c -o $(BUILD)/determinism_tsan $(LDLIBS)
	clang $(STD) $(WARN) -O1 -g -fopenmp -fsanitize=thread $(CHECK_CFLAGS) -I. $(TEST_SRC) -o $(BUILD)/check_fsdem_tsan \
	  $(CHECK_LIBS) $(LDLIBS)
	@archer=$$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | head -1); \
	[ -n "$$archer" ] || { echo "tsan: libarcher.so not found; run: sudo apt-get install -y libomp-dev"; exit 1; }; \
	for t in 2 4; do \
	  TSAN_OPTIONS="halt_on_error=1 ignore_noninstrumented_modules=1" OMP_TOOL_LIBRARIES=$$archer OMP_NUM_THREADS=$$t \
	    $(BUILD)/determinism_tsan > $(BUILD)/determinism.out || exit 1; \
	  diff -q tests/determinism.expected $(BUILD)/determinism.out >/dev/null || { echo "tsan: other hashes at $$t threads"; exit 1; }; \
	  for suite in $(TSAN_SUITES); do \
	    TSAN_OPTIONS="halt_on_error=1 ignore_noninstrumented_modules=1" OMP_TOOL_LIBRARIES=$$archer OMP_NUM_THREADS=$$t \
	      CK_FORK=no CK_RUN_SUITE=$$suite $(BUILD)/check_fsdem_tsan >/dev/null || exit 1; done; \
	done
	@echo "tsan: the determinism scenes and the suites $(TSAN_SUITES) at 2 and 4 threads: no data race"

# Every test under Valgrind, no errors and no leaks. FSDEM_TEST_LIGHT=1 sizes the heavy tests down
# (shorter runs, fewer cases, coarser grids; test_light in tests/fsdem_tests.h) so that the whole
# suite takes minutes instead of hours; each such test then asserts what holds at its smaller size.
valgrind: $(BUILD)/check_fsdem
	CK_FORK=no FSDEM_TEST_LIGHT=1 valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=all -q $(BUILD)/check_fsdem

sanitize: $(TEST_SRC) fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer $(CHECK_CFLAGS) -I. \
	  $(TEST_SRC) -o $(BUILD)/check_fsdem_san $(CHECK_LIBS) $(LDLIBS)
	CK_FORK=no UBSAN_OPTIONS=halt_on_error=1 $(BUILD)/check_fsdem_san

$(BUILD)/examples/%: examples/%.c fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

examples: $(EXAMPLES)

# The headline: water breaking through a pile of cylinders (seed 000's wet collapse), PNG frames
# and ParaView series in build/demo/ (about 50 s of CPU on one core).
$(BUILD)/examples/12_demo_wet_collapse: examples/png_writer.h

demo: $(BUILD)/examples/12_demo_wet_collapse
	@mkdir -p $(BUILD)/demo
	$(BUILD)/examples/12_demo_wet_collapse $(BUILD)/demo

# gnuplot draws the validation plots. Install it when we can, otherwise say exactly how; the cases
# still run without it and the report says that the plots were not drawn.
gnuplot-deps:
	@if ! command -v gnuplot >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing gnuplot: apt-get install -y gnuplot-nox"; \
	    (apt-get install -y gnuplot-nox >/dev/null 2>&1 || (apt-get update >/dev/null && apt-get install -y gnuplot-nox >/dev/null)) \
	      || echo "could not install gnuplot; the report will have no plots; run: sudo apt-get install -y gnuplot-nox"; \
	  else echo "gnuplot is missing; the report will have no plots; run: sudo apt-get install -y gnuplot-nox"; fi; \
	fi

# ---- validation (validation/README.md) ----
# The implementation is compiled once (build/validation/fsdem_impl.o); each case's main.c includes
# fsdem.h without FSDEM_IMPLEMENTATION and links against it. The cases read their reference data from
# VALIDATION_DATA (passed as the first argument; compiled in as the default, so
# build/validation/<case>/run works on its own).
VALIDATION_HEADERS := validation/common.h validation/pic_dambreak.h validation/dambreak_protocol.h \
                      $(wildcard validation/*/case.h)
$(BUILD)/validation/fsdem_impl.o: validation/fsdem_impl.c fsdem.h | $(BUILD)
	$(CC) $(STD) $(WARN) -O2 -I. -c $< -o $@

$(BUILD)/validation/%/main.o: validation/%/main.c $(VALIDATION_HEADERS) fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) -O2 -I. -Ivalidation -DVC_DATA_DIR='"$(abspath $(VALIDATION_DATA))"' -c $< -o $@

$(BUILD)/validation/%/run: $(BUILD)/validation/%/main.o $(BUILD)/validation/fsdem_impl.o
	$(CC) $^ -o $@ $(LDLIBS)

.PRECIOUS: $(BUILD)/validation/%/main.o $(BUILD)/validation/%/run

# `make validate` runs the default tier, `make validate-full` the full one; CASES="a b" names some
# cases. One make target per case, longest first (by the last recorded run), so `make -j2 validate`
# runs two at a time. Everything goes to build/validation[-full]/: each case's output and record
# in <case>/, the report REPORT.md. The status is non-zero when a case failed (a CHECK FAIL or a
# crash), after the report is written. `make validate-publish` (TIER=default or full) then copies
# the records into validation/report-<tier>/ and renders validation/REPORT-<tier>.md, to commit.
CASES ?= $(VALIDATION)
VALIDATE_ORDER_default = $(shell sh validation/tiers.sh order default $(CASES))
VALIDATE_ORDER_full = $(shell sh validation/tiers.sh order full $(CASES))
VALIDATE_RUNS_default = $(addprefix validate-run-default/,$(VALIDATE_ORDER_default))
VALIDATE_RUNS_full = $(addprefix validate-run-full/,$(VALIDATE_ORDER_full))
VALIDATE_OUT_default := $(BUILD)/validation
VALIDATE_OUT_full := $(BUILD)/validation-full

.PHONY: validate validate-full validate-runs-default validate-runs-full validate-report validate-status validate-publish
validate-runs-default: $(VALIDATE_RUNS_default)
validate-runs-full: $(VALIDATE_RUNS_full)
validate-run-default/%: $(BUILD)/validation/%/run FORCE
	@sh validation/tiers.sh run default $* $(VALIDATE_OUT_default) $(abspath $(VALIDATION_DATA))
validate-run-full/%: $(BUILD)/validation/%/run FORCE
	@sh validation/tiers.sh run full $* $(VALIDATE_OUT_full) $(abspath $(VALIDATION_DATA))
FORCE:

validate validate-full: SHELL := /bin/bash
validate validate-full: | $(BUILD) gnuplot-deps
	@tier=$(if $(filter validate-full,$@),full,default); out=$(VALIDATE_OUT_$(if $(filter validate-full,$@),full,default)); \
	cases="$(strip $(CASES))"; start=$$(date +%s); mkdir -p $$out; \
	for c in $$cases; do [ -f validation/$$c/main.c ] || { echo "no validation case '$$c'"; exit 2; }; done; \
	$(MAKE) --no-print-directory validate-runs-$$tier CASES="$$cases"; made=$$?; \
	wall=$$(( $$(date +%s) - start )); \
	rm -f $$out/run.txt; \
	if [ "$$(echo $$cases | tr ' ' '\n' | LC_ALL=C sort | paste -s -d' ')" = "$(sort $(VALIDATION))" ] && [ $$made = 0 ]; then \
	  echo "$$(date -u +%Y-%m-%d) on $$(git rev-parse --short HEAD 2>/dev/null || echo unknown), all $(words $(VALIDATION)) cases," \
	    "make $(or $(filter -j%,$(MAKEFLAGS)),-j1) on $$(nproc) cores: $$wall s of wall time, compilation included" \
	    > $$out/run.txt; fi; \
	sh validation/tiers.sh render $$tier $$out $$out/REPORT.md; \
	echo "validate ($$tier tier): $$(sh validation/tiers.sh verdict $$out $$cases); total wall time" \
	  "$$(( $$(date +%s) - start )) s ($$wall s to the end of the runs, compilation included)"; \
	echo "report: $$out/REPORT.md (make validate-publish$(if $(filter validate-full,$@), TIER=full) commits it to validation/)"; \
	[ $$made = 0 ] && sh validation/tiers.sh verdict $$out $$cases >/dev/null

# The records of the last run of a tier (build/validation[-full]/) into the committed report:
# validation/report-<tier>/ and validation/REPORT-<tier>.md (TIER=default or full).
TIER ?= default
validate-publish:
	@sh validation/tiers.sh publish $(TIER) $(VALIDATE_OUT_$(TIER))
	@mkdir -p validation/report-$(TIER)
	@sh validation/tiers.sh render $(TIER) validation/report-$(TIER) validation/REPORT-$(TIER).md report-$(TIER)/
	@echo "validation/REPORT-$(TIER).md rendered from validation/report-$(TIER)/"

# The committed reports, rendered again from their records (validation/report-<tier>/<case>/): after
# a merge, or to mark blocks stale after fsdem.h changed.
validate-report:
	@for t in default full; do mkdir -p validation/report-$$t; \
	  sh validation/tiers.sh render $$t validation/report-$$t validation/REPORT-$$t.md report-$$t/; done

# Which cases of the committed reports are stale: run on code that has changed since.
validate-status:
	@sh validation/tiers.sh status

# Benchmarks are built for any x86-64 (SSE2) by default; BENCH_FLAGS=-march=native builds them for
# this CPU (wider SIMD lanes in the DEM contact kernel). Rebuild with `make -B bench BENCH_FLAGS=...`.
# They are built with OpenMP (BENCH_OMP; empty for a build without it): dem_column, swe2d, pcg_poisson
# and pic_dambreak run on one thread and then on two, and print speedup_2t.
BENCH_FLAGS ?=
BENCH_OMP ?= -fopenmp
$(BUILD)/bench/%: bench/%/main.c fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) -O3 -DNDEBUG $(BENCH_OMP) $(BENCH_FLAGS) -I. $< -o $@ $(LDLIBS)

# the MPS-DEM and PIC-DEM dam breaks' cases are shared by their validation cases and their benches
$(BUILD)/bench/mpsdem_dambreak: validation/mpsdem_dambreak/case.h
$(BUILD)/bench/picdem_dambreak: validation/picdem_cylinder_dambreak/case.h

bench: $(foreach b,$(BENCHES),$(BUILD)/bench/$(b))
	@for b in $(BENCHES); do echo "== bench/$$b"; (cd $(BUILD)/bench && ./$$b) || exit 1; done

# ---- install and packaging ----
# `make install [PREFIX=/usr/local] [DESTDIR=stage]` installs the header, a pkg-config file and a
# CMake package (INTERFACE target fsdem::fsdem) from packaging/*.in, with the version taken from
# FSDEM_VERSION_STRING in fsdem.h when installing. The files name the final PREFIX (not DESTDIR).
# `make install-check` installs into a temporary prefix and builds and runs a program through
# pkg-config and through find_package (packaging/install-check.sh).
PREFIX       ?= /usr/local
INCLUDEDIR   ?= $(PREFIX)/include
LIBDIR       ?= $(PREFIX)/lib
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
CMAKEDIR     ?= $(LIBDIR)/cmake/fsdem
FSDEM_VERSION = $(shell sed -n 's/^\#define FSDEM_VERSION_STRING "\(.*\)"$$/\1/p' fsdem.h)
PKG_SUBST     = sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@VERSION@|$(FSDEM_VERSION)|g' \
                    -e 's|@INCLUDEDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(INCLUDEDIR))|g'
CMAKE_SUBST   = sed -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|g' -e 's|@VERSION@|$(FSDEM_VERSION)|g'

.PHONY: install-check uninstall
install:
	@test -n "$(FSDEM_VERSION)" || { echo "install: no FSDEM_VERSION_STRING in fsdem.h"; exit 1; }
	install -d "$(DESTDIR)$(INCLUDEDIR)" "$(DESTDIR)$(PKGCONFIGDIR)" "$(DESTDIR)$(CMAKEDIR)"
	install -m 644 fsdem.h "$(DESTDIR)$(INCLUDEDIR)/fsdem.h"
	$(PKG_SUBST) packaging/fsdem.pc.in > "$(DESTDIR)$(PKGCONFIGDIR)/fsdem.pc"
	$(CMAKE_SUBST) packaging/fsdemConfig.cmake.in > "$(DESTDIR)$(CMAKEDIR)/fsdemConfig.cmake"
	$(CMAKE_SUBST) packaging/fsdemConfigVersion.cmake.in > "$(DESTDIR)$(CMAKEDIR)/fsdemConfigVersion.cmake"
	chmod 644 "$(DESTDIR)$(PKGCONFIGDIR)/fsdem.pc" "$(DESTDIR)$(CMAKEDIR)/fsdemConfig.cmake" \
	  "$(DESTDIR)$(CMAKEDIR)/fsdemConfigVersion.cmake"

uninstall:
	rm -f "$(DESTDIR)$(INCLUDEDIR)/fsdem.h" "$(DESTDIR)$(PKGCONFIGDIR)/fsdem.pc" \
	  "$(DESTDIR)$(CMAKEDIR)/fsdemConfig.cmake" "$(DESTDIR)$(CMAKEDIR)/fsdemConfigVersion.cmake"
	-rmdir "$(DESTDIR)$(CMAKEDIR)" 2>/dev/null

install-check:
	MAKE="$(MAKE)" CC="$(CC)" sh packaging/install-check.sh

clean:
	rm -rf $(BUILD)
