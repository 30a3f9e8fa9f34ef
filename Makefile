# Paprsek: the commands a newcomer types. Each target installs the Debian
# packages it needs (apt-get, only when they are missing) and then drives CMake.

BUILD      ?= build
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
BUILD_PKGS  = gcc make cmake pkg-config libpng-dev libcjson-dev
TEST_PKGS   = $(BUILD_PKGS) libembree-dev
FUZZ_PKGS   = $(TEST_PKGS) clang libclang-rt-14-dev

.PHONY: all build demo test deps deps-test bench clean

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

bench: deps-test build
	bash bench/run.sh

clean:
	rm -rf $(BUILD) build-asan build-fuzz
