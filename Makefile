# Thin wrapper over CMake: make deps | build | test | demo | bench | install | clean
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
PREFIX ?= /usr/local
KITTI_DIR ?= $(abspath ../shared/data/kitti)
DEMO_OUT ?= out/demo

# Every Debian package the project needs to build, test and view its results (pcl_viewer).
APT_PACKAGES := build-essential cmake pkg-config libpcl-dev libopencv-dev libeigen3-dev \
                libflann-dev libboost-dev libgtest-dev libbenchmark-dev pcl-tools
# Only the Open3D baseline of `make bench` needs these.
BENCH_PACKAGES := python3-open3d python3-numpy

SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)

.PHONY: all deps deps-bench build test demo bench install clean

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

deps-bench: deps
	$(call apt_install,$(BENCH_PACKAGES))

$(BUILD_DIR)/CMakeCache.txt:
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DMSF_KITTI_DIR=$(KITTI_DIR)

build: $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j$(JOBS)

test: deps
	$(MAKE) build
	cd $(BUILD_DIR) && ctest --output-on-failure -j$(JOBS)

demo: deps
	$(MAKE) build
	bash scripts/demo.sh $(BUILD_DIR)/bin $(DEMO_OUT)

bench: deps-bench
	$(MAKE) build
	bash bench/run_all.sh $(BUILD_DIR)/bin $(KITTI_DIR)

install: build
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

clean:
	rm -rf $(BUILD_DIR)
