# SPDX-License-Identifier: GPL-2.0-or-later
# SEDIMENT: the two commands of the README, and their steps.
#   make demo   installs what is missing, builds, runs the main example and says where its output is
#   make test   installs what is missing, builds, runs every test (also under the sanitizers, the deck
#               tests on LAMMPS built from source with SEDIMENT in its tree and as a plugin, Debian 12's
#               release and the current one, and the documentation site)
#   make docs   the documentation site in build/docs (Sphinx, warnings as errors)
BUILD   ?= build
PYTHON  := /usr/bin/python3
JOBS    ?= 2
OUT     ?= out
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMP_NUM_THREADS := 1
# A rank that stops with an error: mpirun kills the others at once, not a second later (the tests
# stop many runs on purpose; tests/decks/CMakeLists.txt)
export OMPI_MCA_odls_base_sigkill_timeout := 0
# Open MPI's ob1 layer, as the sediment command chooses it (python/sediment/sim/process.py): no fabric
# library loaded at each start (Omni-Path's spends 0.1 s per core timing the clock), 0.35 s -> 0.16 s
# per start of a serial run; the tests start some thousands
export OMPI_MCA_pml := ob1

.PHONY: deps build build-demo demo docs test test-cpp test-python check-sanitize test-lammps-current test-lammps-2022 bench clean

deps:
	@scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# What the demo runs, and no more (no tests, benchmarks or plugin): the driver with its styles
# library, and the Python module.
DEMO_TARGETS := lmp_sediment _core
build-demo: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target $(DEMO_TARGETS)

# Sample 5 of Bravo et al. end to end: the effects planner decides what the test calls for (drag,
# hindrance, parcels, Courant number; its runs take about a minute on 2 cores), then the decided scene
# runs in the D422 column for 24 h of settling, then the hydrometer, buoyancy-sphere and pipette readouts.
# A rerun replaces the demo's previous results.
demo: build-demo
	bin/sediment plan examples/granulometry/psd/sample5.csv --out $(OUT)/sample5/plan --jobs $(JOBS)
	SEDIMENT_RANKS=$(JOBS) SEDIMENT_REPLACE=1 examples/granulometry/run.sh sample5 $(OUT)/sample5 \
	    --plan $(OUT)/sample5/plan/report.json
	@echo "demo output: $(OUT)/sample5/plan (effects.csv, plan.png: what each effect changes and costs) and"
	@echo "             $(OUT)/sample5/readout (granulometry.png/.pdf, hydrometer.csv, buoyancy.csv, pipette.csv, errors.csv)"

test-cpp: build
	cd $(BUILD) && ctest -j $(JOBS) --output-on-failure

# The test files in $(JOBS) workers (pytest-xdist): most tests wait on one single-rank LAMMPS run or on
# Python, so one worker leaves a core idle. No test's outcome depends on the clock or the load; the
# tests of the installed package share one worker and its venv. First the package's imports point one
# way (scripts/check-imports.py, docs/layout.md).
test-python: build
	$(PYTHON) scripts/check-imports.py
	PYTHONPATH=python SEDIMENT_LMP=$(abspath $(BUILD))/lmp_sediment $(PYTHON) -m pytest -q -n $(JOBS) --dist loadgroup \
	  tests/python

# The C++ and deck tests again, built with AddressSanitizer and UndefinedBehaviorSanitizer. No Python
# module there: the deck harness imports the one of $(BUILD). Leak checks are off (LAMMPS and Open MPI
# keep allocations until exit); any memory error or undefined behaviour aborts the test that hit it.
SANITIZE_BUILD ?= build-sanitize
check-sanitize: build
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSEDIMENT_SANITIZE=ON \
	      -DSEDIMENT_BUILD_PYTHON=OFF -DLAMMPS_SOURCE_DIR=$(abspath $(BUILD))/lammps-headers
	@# what its tests run, no more (no plugin), and the benchmarks of the core's kernels, which nothing
	@# else in make test compiles
	cmake --build $(SANITIZE_BUILD) -j $(JOBS) --target test_core lmp_sediment bench_core_kernels
	@# every check serially but soft_bed, and with 2 ranks those that exercise the MPI paths (ghost
	@# atoms, file writing on rank 0, restarts): the full 2-rank set runs uninstrumented in test-cpp.
	@# soft_bed checks physics over long runs (58 s here) on styles the shorter decks run too (fluid
	@# forces with granular contacts and a granular wall: restart_state, struck_ball, the style checks;
	@# compute contact/overlap: contact_overlap)
	cd $(SANITIZE_BUILD) && export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
	  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 && ctest -j $(JOBS) --output-on-failure -E '(\.np2|soft_bed\.np1)$$' && \
	  ctest -j $(JOBS) --output-on-failure -R '(lubrication|layers_hdf5|restart_state|uniform_fast_path)\.np2$$'

# LAMMPS built from Debian's source packages with SEDIMENT installed in the tree (the in-tree route),
# by scripts/build-lammps.sh: the tree and its build are a cache outside the checkout, shared by every
# clone on the machine, built once per machine; a later run reinstalls this checkout's SEDIMENT files
# and recompiles only those.
LAMMPS_CACHE ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/sediment
# The current LAMMPS (Debian sid's source package, about 7 min to build at -j2 the first time): every
# deck test on its lmp (in-tree route; on 2 ranks where it also runs on 1), and this project built
# against it runs the style checks as a plugin loaded at start and through its lmp_sediment (plugin
# and driver routes). Those two without link-time optimisation (SEDIMENT_LTO=OFF): what they check is
# the styles on the release's API, and their LTO links would take two minutes of CPU (the optimised
# plugin is checked on 29 Sep 2021, below).
CURRENT ?= $(LAMMPS_CACHE)/lammps-current
CURRENT_SEDIMENT ?= $(BUILD)/lammps-current-sediment
test-lammps-current: build
	scripts/build-lammps.sh current $(CURRENT)
	cmake -S . -B $(CURRENT_SEDIMENT) -DCMAKE_BUILD_TYPE=Release -DSEDIMENT_BUILD_PYTHON=OFF -DSEDIMENT_LTO=OFF \
	      -DLAMMPS_SOURCE_DIR=$(abspath $(CURRENT))/lammps/src \
	      -DLAMMPS_LIBRARY=$(abspath $(CURRENT))/build/liblammps.so \
	      -DSEDIMENT_DECK_LMP=$(abspath $(CURRENT))/build/lmp >/dev/null
	@# the plugin and the driver, which the route tests run (the core's tests ran in test-cpp)
	cmake --build $(CURRENT_SEDIMENT) -j $(JOBS) --target sedimentplugin lmp_sediment
	@# every deck, on 2 ranks where it runs on 1 and 2 (the release's API runs there as on 1; the
	@# serial runs are test-cpp's and check-sanitize's, on 29 Sep 2021), and the routes
	cd $(CURRENT_SEDIMENT) && ctest -j $(JOBS) -L "deck|route" -LE serial_twin --output-on-failure
	@# the doc pages of the in-tree package are in LAMMPS's command tables: no style entry missing
	$(PYTHON) $(CURRENT)/lammps/doc/utils/check-styles.py > $(CURRENT)/check-styles.txt
	@! grep -E "missing|incomplete" $(CURRENT)/check-styles.txt
	@echo "check-styles: $$(grep 'Total number' $(CURRENT)/check-styles.txt)"
	@# and the package in LAMMPS's package lists
	$(PYTHON) $(CURRENT)/lammps/doc/utils/check-packages.py > $(CURRENT)/check-packages.txt
	@! grep -E "missing" $(CURRENT)/check-packages.txt
	@echo "check-packages: $$(head -1 $(CURRENT)/check-packages.txt), none missing"

# LAMMPS 29 Sep 2021 (Debian 12's release), built from its source package with SEDIMENT in the tree
# (its CMake sets C++11; the package's module raises the lammps target to C++17; about 5 min to build
# at -j2 the first time). The in-tree route on its lmp: the style checks (every style's pinned
# regression and restart replay, 1 and 2 ranks) and the comparison of rank counts. The plugin route
# on the same lmp: $(BUILD)/sedimentplugin.so, the plugin `make build` gives (link-time optimised,
# against the headers of this release's source package: the tree's own), loaded by `plugin load`
# before each deck, runs the style checks on 2 ranks and lists its styles. LAMMPS_2022_SEDIMENT
# only registers these tests: nothing is built there. Every other deck test runs on the same release
# through test-cpp's lmp_sediment (Debian's liblammps). The decks' checks use the Python module of
# $(BUILD).
LAMMPS_2022 ?= $(LAMMPS_CACHE)/lammps-2022
LAMMPS_2022_SEDIMENT ?= $(BUILD)/lammps-2022-sediment
test-lammps-2022: build
	scripts/build-lammps.sh 2022 $(LAMMPS_2022)
	cmake -S . -B $(LAMMPS_2022_SEDIMENT) -DCMAKE_BUILD_TYPE=Release -DSEDIMENT_BUILD_PYTHON=OFF \
	      -DLAMMPS_SOURCE_DIR=$(abspath $(LAMMPS_2022))/lammps/src \
	      -DLAMMPS_LIBRARY=$(abspath $(LAMMPS_2022))/build/liblammps.so \
	      -DSEDIMENT_DECK_LMP=$(abspath $(LAMMPS_2022))/build/lmp \
	      -DSEDIMENT_DECK_PLUGIN=$(abspath $(BUILD))/sedimentplugin.so >/dev/null
	cd $(LAMMPS_2022_SEDIMENT) && ctest -j $(JOBS) -R '^(deck\.(style_|mpi_consistency)|route\.plugin\.)' \
	  --output-on-failure

# The documentation site (Sphinx from Debian's packages, warnings as errors): the README and docs/,
# the style pages, the notebook as a tutorial (executed here with this build, its printed text and
# figures on the page; its run in $(BUILD)/docs-src-notebook) and the Python API from its docstrings.
docs: build
	PYTHONPATH=$(abspath python) SEDIMENT_LMP=$(abspath $(BUILD))/lmp_sediment \
	  $(PYTHON) scripts/docs-stage.py $(BUILD)/docs-src
	SEDIMENT_PYTHON=$(abspath python) $(PYTHON) -m sphinx -W --keep-going -q -b html $(BUILD)/docs-src $(BUILD)/docs
	@echo "docs: $(BUILD)/docs/index.html"

# The phases after the build run two at a time. On its own each leaves the cores idle a tenth to
# half of its time (runs starting, MPI waiting, the one-core notebook and Sphinx), and two side by
# side fill them. The longest start first; each phase's output is printed whole when it ends.
TEST_PHASES := test-python test-cpp check-sanitize test-lammps-current docs test-lammps-2022
test: build
	@echo "make test: $(TEST_PHASES), two at a time; each one's output is printed when it ends"
	@$(MAKE) --no-print-directory -j 2 --output-sync=target $(TEST_PHASES)

# Cost of each effect per particle-step, as ratios measured in one run; the same against the peer at
# every dt/tau from 1e-4 to 1e4; the settling bed with contacts under each law against fix viscous;
# then the core's per-atom kernels (grid deposit and interpolation, Di Felice curve, phi functions).
# Not part of make test.
bench: build
	cmake --build $(BUILD) -j $(JOBS) --target bench_core_kernels
	$(PYTHON) benchmarks/cost.py
	$(PYTHON) benchmarks/cost.py --sweep --particles 20000 --steps 1000 --repeats 3
	$(PYTHON) benchmarks/bed.py --laws standard,dallavalle,stokes --steps 500 --repeats 3
	$(BUILD)/bench_core_kernels --benchmark_min_time=0.2

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) $(OUT) build-pip python/sediment/_core*.so
