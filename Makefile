# The two README commands (`make demo`, `make test`) do all their own set-up.
BUILD ?= build
JOBS  ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: deps build test test-sanitized demo bench fuzz format clean install-addon dev materials

deps:
	bash scripts/setup-deps.sh

# Profile-guided optimisation: an instrumented training build renders the benchmark scenes once
# per build directory (scripts/pgo-train.sh); the real build is optimised with its profile.
# PGO=0 builds without it.
PGO ?= 1
ifeq ($(PGO),1)
PGO_PROFILE := $(abspath $(BUILD))/pgo-profile
PGO_FLAGS := -DGDPT_PGO_USE=$(PGO_PROFILE)
$(BUILD)/CMakeCache.txt: $(PGO_PROFILE)/.trained
$(PGO_PROFILE)/.trained: | deps
	bash scripts/pgo-train.sh $(BUILD)
	touch $@
endif

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(PGO_FLAGS) $(CMAKE_FLAGS)

# A second build of the add-on's module for x86-64-v3 CPUs (AVX2, FMA, BMI2; a few percent
# faster), which the add-on loads when the CPU runs it (scripts/build-variant.sh, built only on
# such a machine). ISA_VARIANTS= skips it.
ISA_VARIANTS ?= x86-64-v3

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)
	@for arch in $(ISA_VARIANTS); do \
	  PGO=$(PGO) JOBS=$(JOBS) CMAKE_FLAGS="$(CMAKE_FLAGS)" \
	    bash scripts/build-variant.sh $(BUILD) $$arch || exit 1; \
	done

install-addon: build
	@if [ -f scripts/install-addon.sh ]; then bash scripts/install-addon.sh $(BUILD); fi

test: build install-addon
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	$(MAKE) test-sanitized

# The C++ unit suites again under AddressSanitizer + UndefinedBehaviorSanitizer (GDPT_SANITIZE, in
# build-asan/: no PGO, no x86-64-v3 variant, no module: Blender's Python cannot load an ASan
# module). A finding aborts its suite. These suites cover the code that reads outside data
# (EXR files, the add-on's arrays, images) and the core's small units; the rendering and
# statistical suites (chi-square, G-PT unbiasedness, renders) are left out: under ASan they
# would take most of CI's 40 minutes on 2 cores for code the fuzzers and unit suites reach.
ASAN_BUILD ?= build-asan
SANITIZED_TESTS ?= test_mesh_ingest test_reconstruct test_image_io test_texture test_material \
                   test_math_node test_procedural_texture test_bsdf_properties test_gradient_shift
test-sanitized: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Release -DGDPT_SANITIZE=ON \
	  -DGDPT_BUILD_PYTHON=OFF -DGDPT_BUILD_BENCH=OFF $(CMAKE_FLAGS)
	cmake --build $(ASAN_BUILD) -j $(JOBS) --target $(SANITIZED_TESTS)
	@for t in $(SANITIZED_TESTS); do \
	  exe=$$(find $(ASAN_BUILD)/tests -name $$t -type f -executable | head -1); \
	  echo "test-sanitized: $$t"; \
	  (cd $$(dirname $$exe) && ./$$t --gtest_brief=1) || exit 1; \
	done

# libFuzzer targets (clang, in build-fuzz/), each run for FUZZ_SECONDS (scripts/fuzz.sh).
FUZZ_SECONDS ?= 60
fuzz: deps
	FUZZ_SECONDS=$(FUZZ_SECONDS) JOBS=$(JOBS) bash scripts/fuzz.sh build-fuzz

demo: build install-addon
	bash scripts/demo.sh $(BUILD)

# Developer loop (CMakePresets.json "dev", in build-dev/): no PGO training, no x86-64-v3 module,
# every test. Not what CI runs: `make test` is.
dev: deps
	cmake --preset dev
	cmake --build --preset dev -j $(JOBS)
	ctest --preset dev -j $(JOBS)

# QUICK=1: only the equal-time report against Cycles, reduced (under ten minutes).
QUICK ?= 0
# KEEP=cycles_default,cycles_unbiased: reuse Cycles' curves of the previous report run.
KEEP ?=
bench: build install-addon
	QUICK=$(QUICK) KEEP=$(KEEP) bash scripts/bench.sh $(BUILD)

# Per-material agreement with Cycles over a library of material scripts and .blend files (not in
# CI), written to bench/results/$(RESULTS).{json,md}:
#   make materials LIB=/path/to/library [ONLY=Name,Name] [RESULTS=materials] [SOURCE='owner/repo@commit (licence)']
RESULTS ?= materials
materials: build
	RESULTS=$(RESULTS) bash bench/materials/run.sh $(BUILD) "$(LIB)" $(if $(ONLY),--only "$(ONLY)") $(if $(SOURCE),--source "$(SOURCE)")

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD)
