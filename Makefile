# fsdem.h build: tests, valgrind, sanitizers, examples, demo, validation, benchmarks.
# Everything is built into build/. `make help` lists the targets.

CC      ?= cc
CXX     ?= c++
WARN    := -Wall -Wextra -Wpedantic
CFLAGS  ?= -O2 -g
STD     := -std=c99
LDLIBS  := -lm
BUILD   := build
SHARED  ?= ../shared

CHECK_CFLAGS = $(shell pkg-config --cflags check 2>/dev/null)
CHECK_LIBS   = $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lrt -lpthread -lm)

# one file per suite registered in tests/check_main.c
TEST_SRC   := tests/test_core.c tests/test_dem.c tests/test_linalg.c tests/test_pic.c tests/test_swe.c tests/test_couple_swe.c tests/test_io.c tests/check_main.c tests/fsdem_impl.c
EXAMPLES   := $(patsubst examples/%.c,$(BUILD)/examples/%,$(wildcard examples/*.c))
VALIDATION := $(patsubst validation/%/main.c,%,$(wildcard validation/*/main.c))
BENCHES    := $(patsubst bench/%/main.c,%,$(wildcard bench/*/main.c))

.PHONY: all help test check-deps compile-checks valgrind sanitize examples demo validate bench install clean

all: $(BUILD)/check_fsdem examples

help:
	@echo "make test       Check suite (installs Check with apt-get when missing and run as root)"
	@echo "make valgrind   the suite under Valgrind (no errors, no leaks)"
	@echo "make sanitize   the suite with AddressSanitizer and UndefinedBehaviorSanitizer"
	@echo "make demo       the headline example (cylinder-layer collapse) in under a minute"
	@echo "make examples   all examples"
	@echo "make validate   every validation case; report in build/validation/REPORT.md"
	@echo "make bench      throughput benchmarks (BENCH lines); BENCH_FLAGS=-march=native for this CPU"
	@echo "make install    copy fsdem.h to PREFIX/include (PREFIX=/usr/local)"

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
	@echo "compile checks: gcc and clang (C99: double, float, AVX-512 lanes, no SIMD), $(CXX) and clang++: warning-free"

test: compile-checks $(BUILD)/check_fsdem
	$(BUILD)/check_fsdem

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

$(BUILD)/validation/%/run: validation/%/main.c fsdem.h | $(BUILD)
	@mkdir -p $(dir $@)
	$(CC) $(STD) $(WARN) -O2 -I. -Ivalidation $< -o $@ $(LDLIBS)

validate: SHELL := /bin/bash
validate: $(foreach v,$(VALIDATION),$(BUILD)/validation/$(v)/run)
	@status=0; for v in $(VALIDATION); do \
	  echo "== validation/$$v"; \
	  (cd $(BUILD)/validation/$$v && ./run $(abspath $(SHARED))/refdata) | tee $(BUILD)/validation/$$v/checks.txt; \
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

PREFIX ?= /usr/local
install:
	install -d $(DESTDIR)$(PREFIX)/include
	install -m 644 fsdem.h $(DESTDIR)$(PREFIX)/include/fsdem.h

clean:
	rm -rf $(BUILD)
