# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Thin wrapper over CMake: make deps | deps-slurm | build | test | test-sanitize | fuzz | config-files | demo | bench |
# docs | install | clean
SHELL := /bin/bash
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
PREFIX ?= /usr/local
KITTI_DIR ?= $(abspath ../shared/data/kitti)
DEMO_OUT ?= out/demo

# The Python module msfusion (python/) and its tests and examples (matplotlib). Open3D
# (python3-open3d) is optional: msfusion.o3d and its test use it when it is installed.
PYTHON_PACKAGES := pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-yaml
# The ros module (bag reader, msf_kitti2bag, msf_ros_node) and its tests: Debian's ROS 1
# (roscore, rosbag, roslaunch, rostopic in ros-core; the C++ libraries and messages), and
# procps (pgrep, ps) with which the node's test makes sure nothing it started is left;
# python3-sensor-msgs, with which rostopic counts the depth images the node publishes.
ROS_PACKAGES := ros-core libroscpp-dev librosbag-dev libtf2-ros-dev libtf2-msgs-dev libmessage-filters-dev \
                libsensor-msgs-dev libvisualization-msgs-dev libcv-bridge-dev libpcl-conversions-dev procps \
                python3-sensor-msgs
# Every Debian package the project needs to build, test and view its results (pcl_viewer);
# time: GNU time, which the bad-input matrix measures each case's memory with; python3-yaml:
# PyYAML, which a test reads and writes the configuration files with.
APT_PACKAGES := build-essential cmake pkg-config libpcl-dev libopencv-dev libeigen3-dev \
                libflann-dev libboost-dev libgtest-dev libbenchmark-dev pcl-tools time \
                libyaml-cpp-dev $(PYTHON_PACKAGES) $(ROS_PACKAGES)
# A single-node Slurm cluster on localhost (scripts/slurm_local.sh), which the batch's tests
# submit to (tests/batch/test_slurm.cpp; .ci/run starts it before `make test`).
SLURM_PACKAGES := slurm-wlm munge
# Only `make fuzz` needs these: clang's libFuzzer, and an OpenMP runtime for clang (the
# project's code no longer uses OpenMP, but the fuzz build was not tried without it).
FUZZ_PACKAGES := clang libomp-dev
# Only the Open3D baseline of `make bench` needs these.
BENCH_PACKAGES := python3-open3d python3-numpy
# Only `make docs` needs this: the API reference from the headers' comments (docs/Doxyfile).
DOCS_PACKAGES := doxygen

SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)

.PHONY: all deps deps-slurm deps-bench deps-fuzz deps-docs docs build test test-sanitize test-sanitize-fast fuzz demo bench \
        install clean config-files

# `make test-sanitize`: the whole suite built with AddressSanitizer and UndefinedBehavior-
# Sanitizer (float-cast-overflow included), the first report fatal.
SANITIZE_BUILD_DIR ?= build-sanitize
SANITIZE_FLAGS := -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all \
                  -fno-omit-frame-pointer
# `make fuzz`: each libFuzzer target of fuzz/ runs FUZZ_SECONDS from a seed corpus made of
# the KITTI sample (and the configuration files); crashes land in $(FUZZ_BUILD_DIR)/findings/<target>/.
# Inputs are up to 64 KB, up to FUZZ_PLY_MAX_LEN for ply, whose header check reads 64 KB, and
# up to FUZZ_YAML_MAX_LEN for config and calibration (the YAML readers: configuration, rig and
# camera files): larger inputs reach those limits and what lies beyond them (a YAML file nested
# deeply enough to reach yaml-cpp's depth guard in every form is larger than 64 KB).
FUZZ_BUILD_DIR ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_TARGETS := cloud ply calibration poses velodyne config
FUZZ_PLY_MAX_LEN ?= 262144
FUZZ_YAML_MAX_LEN ?= 1048576

all: build

# Installs what is missing, skips what is present.
define apt_install
	@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing; \
	else echo "deps: all present"; fi
endef

deps:
	$(call apt_install,$(APT_PACKAGES))

deps-slurm: deps
	$(call apt_install,$(SLURM_PACKAGES))

deps-bench: deps
	$(call apt_install,$(BENCH_PACKAGES))

deps-fuzz: deps
	$(call apt_install,$(FUZZ_PACKAGES))

deps-docs:
	$(call apt_install,$(DOCS_PACKAGES))

$(BUILD_DIR)/CMakeCache.txt:
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DMSF_KITTI_DIR=$(KITTI_DIR)

build: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j$(JOBS)

test: deps deps-slurm
	$(MAKE) build
	cd $(BUILD_DIR) && ctest --output-on-failure -j$(JOBS)

# Third-party reports are suppressed by name in tests/sanitize/*.supp (each with its reason).
# PCL's vtk2mesh alloc-dealloc mismatch, which GCC 12's ASan cannot suppress by name, is let
# through for the two tests that load a .vtk mesh only (tests/sanitize/per_test_options.cmake.in).
# -Wno-maybe-uninitialized: GCC 12 warns inside libstdc++'s std::regex under -fsanitize (a
# false positive that -Werror would make fatal).
SANITIZE_CONFIGURE = cmake -S . -B $(SANITIZE_BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DMSF_KITTI_DIR=$(KITTI_DIR) \
  -DMSF_BUILD_BENCH=OFF -DMSF_BUILD_PYTHON=OFF -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS) -Wno-maybe-uninitialized" -DCMAKE_C_FLAGS="$(SANITIZE_FLAGS)" \
  -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_SHARED_LINKER_FLAGS="$(SANITIZE_FLAGS)"
# A report goes to stderr (no log_path), where the tests look for it in every tool they run
# (runCommand in tests/support, bad_inputs.sh) and fail quoting it; abort_on_error=1 for ASan and
# UBSan (whose first report is fatal, -fno-sanitize-recover=all), so that a stopped tool dies of
# SIGABRT instead of exiting 1 as a clear error does.
SANITIZE_CTEST = cd $(SANITIZE_BUILD_DIR) && \
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:suppressions=$(CURDIR)/tests/sanitize/asan.supp \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitize/lsan.supp \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:abort_on_error=1:suppressions=$(CURDIR)/tests/sanitize/ubsan.supp \
  ctest --output-on-failure -j$(JOBS) --timeout 1500

test-sanitize: deps
	$(SANITIZE_CONFIGURE) -DCMAKE_DISABLE_PRECOMPILE_HEADERS=OFF
	cmake --build $(SANITIZE_BUILD_DIR) -j$(JOBS)
	$(SANITIZE_CTEST) $(CTEST_ARGS)

# The fast subset .ci/run runs: the file readers and their tools (tests labelled common, io),
# built without the precompiled headers, so that a file missing an include of its own fails,
# and every public header compiled alone (msf_header_check).
test-sanitize-fast: deps
	$(SANITIZE_CONFIGURE) -DCMAKE_DISABLE_PRECOMPILE_HEADERS=ON -DMSF_CHECK_HEADERS=ON
	cmake --build $(SANITIZE_BUILD_DIR) -j$(JOBS) --target test_common test_io msf_info msf_kitti2pcd msf_pcd2png \
	  msf_header_check
	$(SANITIZE_CTEST) -L '^(common|io)$$'

fuzz: deps-fuzz
	cmake -S . -B $(FUZZ_BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_CXX_COMPILER=clang++ -DMSF_BUILD_TESTS=OFF -DMSF_BUILD_TOOLS=OFF -DMSF_BUILD_BENCH=OFF \
	  -DMSF_BUILD_PYTHON=OFF -DMSF_BUILD_FUZZ=ON -DMSF_WARNINGS_AS_ERRORS=OFF \
	  -DCMAKE_CXX_FLAGS="-g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all"
	cmake --build $(FUZZ_BUILD_DIR) -j$(JOBS) --target fuzz_all
	python3 fuzz/make_corpus.py $(KITTI_DIR) $(FUZZ_BUILD_DIR)/seeds
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FUZZ_BUILD_DIR)/corpus/$$t $(FUZZ_BUILD_DIR)/findings/$$t; \
	  case $$t in ply) max_len=$(FUZZ_PLY_MAX_LEN);; config | calibration) max_len=$(FUZZ_YAML_MAX_LEN);; \
	    *) max_len=65536;; esac; \
	  echo "== fuzz_$$t: $(FUZZ_SECONDS) s, inputs up to $$max_len bytes"; \
	  ASAN_OPTIONS=detect_leaks=0 $(FUZZ_BUILD_DIR)/fuzz/fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -max_len=$$max_len \
	    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
	    -artifact_prefix=$(FUZZ_BUILD_DIR)/findings/$$t/ \
	    $(FUZZ_BUILD_DIR)/corpus/$$t $(FUZZ_BUILD_DIR)/seeds/$$t 2>&1 | \
	    tee $(FUZZ_BUILD_DIR)/fuzz_$$t.log | grep -E "^(#[0-9]+ *DONE|stat::number_of_executed_units|stat::average_exec_per_sec|==[0-9]+==ERROR|SUMMARY)" ; \
	  test $${PIPESTATUS[0]} -eq 0 || { echo "fuzz_$$t found a crash: $(FUZZ_BUILD_DIR)/findings/$$t/"; exit 1; }; \
	done

# The files made from the configuration keys' declarations in the code: config/kitti.yaml,
# synthetic.yaml, paper.yaml and docs/configuration.md (a test fails when one is out of date).
config-files: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j$(JOBS) --target msf_config
	$(BUILD_DIR)/bin/msf_config -write .

demo: deps
	$(MAKE) build
	bash scripts/demo.sh $(BUILD_DIR)/bin $(DEMO_OUT)

bench: deps-bench
	$(MAKE) build
	bash bench/run_all.sh $(BUILD_DIR)/bin $(KITTI_DIR)

# The API reference in $(BUILD_DIR)/docs/html (warnings in $(BUILD_DIR)/docs/warnings.log).
docs: deps-docs
	mkdir -p $(BUILD_DIR)/docs
	MSF_DOCS_DIR=$(abspath $(BUILD_DIR))/docs doxygen docs/Doxyfile
	@echo "docs: $(BUILD_DIR)/docs/html/index.html ($$(grep -c 'warning:' $(BUILD_DIR)/docs/warnings.log || true) warnings)"

install: build
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

clean:
	rm -rf $(BUILD_DIR) $(SANITIZE_BUILD_DIR) $(FUZZ_BUILD_DIR)
