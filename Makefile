# Paprsek: the commands a newcomer types. Each target installs the Debian
# packages it needs (apt-get, only when they are missing) and then drives CMake.

BUILD      ?= build
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
BUILD_PKGS  = gcc make cmake pkg-config libpng-dev libcjson-dev
TEST_PKGS   = $(BUILD_PKGS) libembree-dev
FUZZ_PKGS   = $(TEST_PKGS) clang libclang-rt-14-dev libomp-14-dev
FUZZ_SECONDS ?= 60
FUZZERS     = obj mtl json render

.PHONY: all build demo test deps deps-test bench clean build-asan sanitize fuzz

all: build

# Installs the named packages that dpkg does not report as installed.
define ensure_pkgs
	@missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" != 0 ]; then echo "run as root, or install:$$missing" >&2; exit 1; fi; \
	  apt-get install -y $$missing || { apt-get update && apt-get install -y $$missing; } || exit 1; \
	fi
endef

deps:
	$(call ensure_pkgs,$(BUILD_PKGS))

deps-test:
	$(call ensure_pkgs,$(TEST_PKGS))

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	./$(BUILD)/paprsek render -o cornell.png --stats

test: deps-test
	@# (re)configure so that a newly installed Embree is found
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

# AddressSanitizer + UndefinedBehaviorSanitizer build of the library, the
# program and the tests (build-asan/paprsek); `make sanitize` runs the suite.
build-asan: deps-test
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPK_SANITIZE=ON
	cmake --build build-asan -j $(JOBS)

sanitize: build-asan
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --test-dir build-asan --output-on-failure -j $(JOBS)

# libFuzzer harnesses (clang, ASan+UBSan), each run for FUZZ_SECONDS over its
# corpus in tests/fuzz/corpus/<name>, seeded from tests/data and ../shared.
# Crashers are written to build-fuzz/crashers/<name>/.
fuzz:
	$(call ensure_pkgs,$(FUZZ_PKGS))
	CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPK_FUZZ=ON -DPK_WITH_EMBREE=OFF
	cmake --build build-fuzz -j $(JOBS)
	@for f in $(FUZZERS); do \
	  mkdir -p tests/fuzz/corpus/$$f build-fuzz/crashers/$$f; \
	  echo "== fuzz_$$f for $(FUZZ_SECONDS) s"; \
	  ./build-fuzz/tests/fuzz_$$f -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
	    -artifact_prefix=build-fuzz/crashers/$$f/ -print_final_stats=1 \
	    tests/fuzz/corpus/$$f tests/data ../shared/scenes/cornell 2>&1 | grep -E 'stat::|Done|ERROR|cov:' | tail -n 8; \
	done

bench: deps-test build
	bash bench/run.sh

clean:
	rm -rf $(BUILD) build-asan build-fuzz
