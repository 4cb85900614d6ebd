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

.PHONY: all help test check-deps gnuplot-deps compile-checks map-check determinism valgrind sanitize examples demo validate bench install clean

all: $(BUILD)/check_fsdem examples

help:
	@echo "make test       Check suite (installs Check with apt-get when missing and run as root)"
	@echo "make test-float the Check suite with fsdem_real = float (-DFSDEM_USE_FLOAT)"
	@echo "make determinism  the same results from gcc and clang at -O0/-O2/-march=native/no SIMD"
	@echo "make valgrind   the suite under Valgrind (no errors, no leaks)"
	@echo "make sanitize   the suite with AddressSanitizer and UndefinedBehaviorSanitizer"
	@echo "make demo       the headline example (cylinder-layer collapse) in under a minute"
	@echo "make examples   all examples"
	@echo "make validate   every validation case; report and plots in build/validation/REPORT.md"
	@echo "                 (installs gnuplot-nox with apt-get when missing and run as root)"
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

# The map of fsdem.h (its >>tag banners) is exact, and the float build's symbol list complete.
map-check:
	@sh tests/map_check.sh fsdem.h

test: map-check compile-checks $(BUILD)/check_fsdem
	$(BUILD)/check_fsdem

# The same results bit for bit from gcc and clang at -O0, -O2, -O2 -march=native and without SIMD:
# tests/determinism.c prints a hash of each solver's saved state, pinned in tests/determinism.expected
# (regenerate it, with the reason in the commit, when a change of the numerics is intended).
DETERMINISM_FLAGS := "-O0" "-O2" "-O2 -march=native" "-O2 -DFSDEM_NO_SIMD"
determinism: | $(BUILD)
	@for c in gcc clang; do if command -v $$c >/dev/null; then for f in $(DETERMINISM_FLAGS); do \
	  $$c $(STD) $(WARN) $$f -I. tests/determinism.c -o $(BUILD)/determinism $(LDLIBS) || exit 1; \
	  $(BUILD)/determinism > $(BUILD)/determinism.out || exit 1; \
	  if ! diff -q tests/determinism.expected $(BUILD)/determinism.out >/dev/null; then \
	    echo "determinism: $$c $$f gives other results:"; diff tests/determinism.expected $(BUILD)/determinism.out; exit 1; fi; \
	done; fi; done
	@echo "determinism: gcc and clang at $(DETERMINISM_FLAGS): every solver's state hash as pinned"

# The same suite with fsdem_real = float; its tolerances follow the precision (tests/fsdem_tests.h).
.PHONY: test-float
$(BUILD)/check_fsdem_float: $(TEST_SRC) tests/fsdem_tests.h fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) $(CFLAGS) -DFSDEM_USE_FLOAT $(CHECK_CFLAGS) -I. $(TEST_SRC) -o $@ $(CHECK_LIBS) $(LDLIBS)

test-float: $(BUILD)/check_fsdem_float
	$(BUILD)/check_fsdem_float

valgrind: $(BUILD)/check_fsdem
	CK_FORK=no valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=all -q $(BUILD)/check_fsdem

sanitize: $(TEST_SRC) fsdem.h | $(BUILD) check-deps
	$(CC) $(STD) $(WARN) -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer $(CHECK_CFLAGS) -I. \
	  $(TEST_SRC) -o $(BUILD)/check_fsdem_san $(CHECK_LIBS) $(LDLIBS)
	CK_FORK=no UBSAN_OPTIONS=halt_on_error=1 $(BUILD)/check_fsdem_san

$(BUILD)/examples/%: examples/%.c fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) $(CFLAGS) -I. $< -o $@ $(LDLIBS)

examples: $(EXAMPLES)

demo: $(BUILD)/examples/01_cylinder_collapse
	cd $(BUILD)/examples && ./01_cylinder_collapse

# gnuplot draws the validation plots. Install it when we can, otherwise say exactly how; the cases
# still run without it and validation/report.sh says that the plots were not drawn.
gnuplot-deps:
	@if ! command -v gnuplot >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing gnuplot: apt-get install -y gnuplot-nox"; \
	    (apt-get install -y gnuplot-nox >/dev/null 2>&1 || (apt-get update >/dev/null && apt-get install -y gnuplot-nox >/dev/null)) \
	      || echo "could not install gnuplot; the report will have no plots; run: sudo apt-get install -y gnuplot-nox"; \
	  else echo "gnuplot is missing; the report will have no plots; run: sudo apt-get install -y gnuplot-nox"; fi; \
	fi

# The cases read their reference data from VALIDATION_DATA (passed as the first argument; compiled in
# as the default, so build/validation/<case>/run works on its own).
$(BUILD)/validation/%/run: validation/%/main.c validation/common.h validation/pic_dambreak.h validation/dambreak_protocol.h fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) -O2 -I. -Ivalidation -DVC_DATA_DIR='"$(abspath $(VALIDATION_DATA))"' $< -o $@ $(LDLIBS)

# the MPS-DEM dam break's case is shared by its validation case and its bench
$(BUILD)/validation/mpsdem_dambreak/run $(BUILD)/bench/mpsdem_dambreak: validation/mpsdem_dambreak/case.h
# the PIC-DEM cylinder dam break's case is shared by its validation case and its bench
$(BUILD)/validation/picdem_cylinder_dambreak/run $(BUILD)/bench/picdem_dambreak: validation/picdem_cylinder_dambreak/case.h

validate: SHELL := /bin/bash
validate: $(foreach v,$(VALIDATION),$(BUILD)/validation/$(v)/run) | gnuplot-deps
	@status=0; for v in $(VALIDATION); do \
	  echo "== validation/$$v"; \
	  (cd $(BUILD)/validation/$$v && ./run $(abspath $(VALIDATION_DATA))) | tee $(BUILD)/validation/$$v/checks.txt; \
	  [ $${PIPESTATUS[0]} -eq 0 ] || status=1; \
	done; sh validation/report.sh $(BUILD)/validation; exit $$status

# Benchmarks are built for any x86-64 (SSE2) by default; BENCH_FLAGS=-march=native builds them for
# this CPU (wider SIMD lanes in the DEM contact kernel). Rebuild with `make -B bench BENCH_FLAGS=...`.
BENCH_FLAGS ?=
$(BUILD)/bench/%: bench/%/main.c fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) -O3 -DNDEBUG $(BENCH_FLAGS) -I. $< -o $@ $(LDLIBS)

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
