# The two README commands (`make demo`, `make test`) do all their own set-up.
BUILD ?= build
JOBS  ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: deps build test demo bench fuzz format clean install-addon dev

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
bench: build install-addon
	QUICK=$(QUICK) bash scripts/bench.sh $(BUILD)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD)
