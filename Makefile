# hpose: `make run` and `make test` work on a fresh Debian bookworm machine: they install the
# missing system packages (as root, or through sudo), configure and build (Release), then run.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)

PACKAGES := build-essential cmake ninja-build lld pkg-config ccache git \
  libeigen3-dev libpcl-dev liboctomap-dev libopencv-dev libpng-dev libjpeg-dev libtiff-dev \
  libopenni2-dev libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc \
  nlohmann-json3-dev libyaml-cpp-dev liburdfdom-dev libassimp-dev libgtest-dev libgmock-dev \
  libbenchmark-dev python3 python3-grpcio python3-protobuf python3-numpy python3-venv \
  python3-setuptools python3-pip opencv-doc openssl systemd \
  libspdlog-dev chromium chromium-driver python3-selenium prometheus

# New build directories use Ninja; an existing one keeps the generator it was made with.
generator = $(if $(wildcard $(1)/CMakeCache.txt),,-G Ninja)

SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps configure build run demo test test-release bench templates python-stubs format \
  clean san-configure fuzz test-asan package

all: build

deps:
	@missing=""; for p in $(PACKAGES) $(EXTRA_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "== installing:$$missing"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	else echo "== system packages present"; fi

configure: deps
	@cmake -S . -B $(BUILD_DIR) $(call generator,$(BUILD_DIR)) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) \
	  > $(BUILD_DIR).configure.log 2>&1 \
	  || { cat $(BUILD_DIR).configure.log; exit 1; }

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: simulate a short recording of a humanoid turning among clutter, serve it with
# hposed on loopback (looped, shipped templates) and show the streamed estimates.
run: build
	@./$(BUILD_DIR)/tools/hpose simulate --out $(BUILD_DIR)/demo-recording --frames 12 --turn-deg 30 \
	  --clutter 3 --no-cloud > /dev/null
	@echo "== hposed serving $(BUILD_DIR)/demo-recording on 127.0.0.1:50051; streaming 20 estimates"
	@./$(BUILD_DIR)/server/hposed --source $(BUILD_DIR)/demo-recording --loop --fps 5 & pid=$$!; \
	  ./$(BUILD_DIR)/tools/hpose query stream --count 20; s=$$?; \
	  kill -INT $$pid; wait $$pid; exit $$s

# One simulated frame, estimated and drawn (build/demo.png).
demo: build
	./$(BUILD_DIR)/tools/hpose demo --picture $(BUILD_DIR)/demo.png

# Every test: the Release suite, then the same suite under AddressSanitizer and
# UndefinedBehaviorSanitizer with every fuzz target run TEST_FUZZ_SECONDS (`make test-asan`; its
# cost is in docs/RELIABILITY.md). Each part ends in CTest's summary; the first failure stops.
test: test-release test-asan

test-release: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# Debian packages of this build (CPack): $(BUILD_DIR)/hpose_*.deb (programs, templates,
# /etc/hpose/hposed.yaml, hposed.service) and hpose-dev_*.deb (C++ client library). See
# docs/INSTALL.md.
package: build
	cmake --build $(BUILD_DIR) --target package

bench: build
	./$(BUILD_DIR)/bench/accuracy_bench

# Regenerates the Python client's gRPC modules (python/hpose/v1/*_pb2*.py, committed so that
# `pip install ./python` needs no compiler) from proto/ with Debian's protoc and
# grpc_python_plugin. A test fails when they differ from what the build generates.
python-stubs: deps
	protoc -I proto --python_out=python --grpc_out=python \
	  --plugin=protoc-gen-grpc=$$(command -v grpc_python_plugin) proto/hpose/v1/pose_service.proto

# Regenerates the shipped templates from the parametric humanoid (see templates/README.md).
templates: configure
	cmake --build $(BUILD_DIR) --target hpose -j $(JOBS)
	./$(BUILD_DIR)/tools/hpose template generate --pose standing --out templates/standing.bt
	./$(BUILD_DIR)/tools/hpose template generate --pose right_arm_raised \
	  --out templates/right_arm_raised.bt
	./$(BUILD_DIR)/tools/hpose template generate --pose arms_swung --out templates/arms_swung.bt

# The sanitized build: clang with AddressSanitizer and UndefinedBehaviorSanitizer over the whole
# project (tests and fuzz targets; no benchmarks) and libFuzzer's coverage over the code fuzzed
# inputs steer (readers, depth stages, daemon), in $(SAN_DIR). One build serves both
# `make test-asan` and `make fuzz` (see docs/RELIABILITY.md for its cost).
SAN_DIR ?= build-san
FUZZ_SECONDS ?= 60
SAN_PACKAGES := clang libclang-rt-14-dev
SAN_FLAGS := -O1 -gline-tables-only -DNDEBUG
# Leaks inside the third-party OpenNI2 library (and its drivers) are suppressed, nothing else.
SAN_ENV := LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp \
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
san-configure: deps
	@$(MAKE) --no-print-directory deps EXTRA_PACKAGES="$(SAN_PACKAGES)"
	@CC=clang CXX=clang++ cmake -S . -B $(SAN_DIR) $(call generator,$(SAN_DIR)) \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$(SAN_FLAGS)" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$(SAN_FLAGS)" \
	  -DHPOSE_FUZZ=ON -DHPOSE_BUILD_BENCH=OFF -DHPOSE_FUZZ_SECONDS=$(FUZZ_SECONDS) \
	  > $(SAN_DIR).configure.log 2>&1 || { cat $(SAN_DIR).configure.log; exit 1; }

# libFuzzer targets for every file reader and the Estimate request path, seeded with real files;
# each runs FUZZ_SECONDS (default 60), JOBS at a time.
fuzz: san-configure
	cmake --build $(SAN_DIR) -j $(JOBS) --target fuzz_targets hpose hpose_proto_python
	cd $(SAN_DIR) && $(SAN_ENV) ctest --output-on-failure -j $(JOBS) -L fuzz

# The whole test suite under the sanitizers, and every fuzz target for TEST_FUZZ_SECONDS (a
# short run with the suite, seeded as `make fuzz` seeds; `make fuzz` runs longer).
TEST_FUZZ_SECONDS ?= 10
test-asan: san-configure
	cmake --build $(SAN_DIR) -j $(JOBS)
	cd $(SAN_DIR) && $(SAN_ENV) HPOSE_FUZZ_SECONDS=$(TEST_FUZZ_SECONDS) \
	  ctest --output-on-failure -j $(JOBS)

format:
	clang-format -i $$(git ls-files '*.cc' '*.h')

clean:
	rm -rf $(BUILD_DIR) $(BUILD_DIR).configure.log $(SAN_DIR) $(SAN_DIR).configure.log
