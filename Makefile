# The two README commands (`make demo`, `make test`) do all their own set-up.
BUILD ?= build
JOBS  ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: deps build test demo bench fuzz format clean install-addon

deps:
	bash scripts/setup-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

install-addon: build
	@if [ -f scripts/install-addon.sh ]; then bash scripts/install-addon.sh $(BUILD); fi

test: build install-addon
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

demo: build install-addon
	bash scripts/demo.sh $(BUILD)

bench: build
	bash scripts/bench.sh $(BUILD)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD)
