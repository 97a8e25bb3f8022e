# SEDIMENT: the two commands of the README, and their steps.
#   make demo   installs what is missing, builds, runs the main example and says where its output is
#   make test   installs what is missing, builds, runs every test
BUILD   ?= build
PYTHON  := /usr/bin/python3
JOBS    ?= 2
OUT     ?= out
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMP_NUM_THREADS := 1

.PHONY: deps build demo test test-cpp test-python bench clean

deps:
	@scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	bin/sediment case-a --out $(OUT)/case_a
	@echo "demo output: $(OUT)/case_a (case_a_velocity.png, case_a_errors.csv)"

test-cpp: build
	cd $(BUILD) && ctest -j $(JOBS) --output-on-failure

test-python: build
	PYTHONPATH=python SEDIMENT_LMP=$(abspath $(BUILD))/lmp_sediment $(PYTHON) -m pytest -q tests/python

test: test-cpp test-python

# Cost of each effect per particle-step, as ratios measured in one run (not part of make test).
bench: build
	$(PYTHON) benchmarks/cost.py

clean:
	rm -rf $(BUILD) $(OUT) python/sediment/_core*.so
