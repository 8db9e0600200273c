# The README's commands. Each one installs what is missing, configures and builds into build/.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test test-sanitize test-container demo bench report python format clean

all: build

# The peer engines (bench) are installed for the tests too: the quick report in `make test`
# measures them beside ours.
deps:
	@scripts/install-deps core service viewer dds bench mcap python

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

demo: build
	@scripts/demo $(BUILD_DIR)

# The suite under AddressSanitizer with UndefinedBehaviorSanitizer (all of it), then the server's
# core under ThreadSanitizer (docs/SERVICE.md says why not the rest).
test-sanitize: deps
	@cmake -S . -B $(BUILD_DIR)-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTUMBLE_SANITIZE=address -DTUMBLE_BUILD_BENCH=OFF >/dev/null
	@cmake --build $(BUILD_DIR)-asan -j $(JOBS)
	@cd $(BUILD_DIR)-asan && ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp ctest --output-on-failure -j $(JOBS)
	@cmake -S . -B $(BUILD_DIR)-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTUMBLE_SANITIZE=thread -DTUMBLE_BUILD_BENCH=OFF >/dev/null
	@cmake --build $(BUILD_DIR)-tsan -j $(JOBS) --target test_world_host
	@cd $(BUILD_DIR)-tsan && OMP_NUM_THREADS=1 TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -j $(JOBS) -R '^(Mailbox|WorldHost)[.]'

# The images of docker/Dockerfile built and run with podman (docker/test says what it checks;
# about 7 minutes on 2 cores from nothing, most of it compiling inside the image).
test-container:
	@scripts/install-deps container
	@docker/test

# The Python client into $(BUILD_DIR)/python (docs/PYTHON.md): PYTHONPATH=$(BUILD_DIR)/python.
python:
	@scripts/install-deps core service python
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD_DIR) --target tumble_python
	@echo "python: PYTHONPATH=$(BUILD_DIR)/python /usr/bin/python3 -c 'import tumble'"

bench: CMAKE_FLAGS += -DTUMBLE_BENCH_PEERS=ON
bench:
	@scripts/install-deps core service viewer bench python
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DTUMBLE_BENCH_PEERS=ON >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)
	@scripts/run-bench $(BUILD_DIR)

# Error against run time and stability on extreme cases, ours beside Bullet, ODE and MuJoCo:
# docs/report/REPORT.md with its CSV and plots (about 20 minutes; QUICK=1: about 1 minute, into
# build/report-quick unless REPORT_DIR is given).
QUICK ?=
REPORT_DIR ?= $(if $(QUICK),$(BUILD_DIR)/report-quick,docs/report)
report:
	@scripts/install-deps core service viewer bench report
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target tumble-report
	@$(if $(QUICK),,echo "report: rewrites the committed docs/report/ (git diff docs/report shows what changed); QUICK=1 writes into $(BUILD_DIR)/report-quick instead")
	@$(BUILD_DIR)/bench/tumble-report $(if $(QUICK),--quick) --out $(REPORT_DIR) \
	  --commit $$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
	@/usr/bin/python3 scripts/report-plots $(REPORT_DIR)
	@echo "report: $(REPORT_DIR)/REPORT.md"

format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf $(BUILD_DIR)
