# The README's commands. Each one installs what is missing, configures and builds into build/.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test demo bench format clean

all: build

deps:
	@scripts/install-deps core service

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

demo: build
	@$(BUILD_DIR)/apps/tumble-run

bench: CMAKE_FLAGS += -DTUMBLE_BENCH_PEERS=ON
bench:
	@scripts/install-deps core service bench
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DTUMBLE_BENCH_PEERS=ON >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)
	@scripts/run-bench $(BUILD_DIR)

format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf $(BUILD_DIR)
