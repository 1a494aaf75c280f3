# Entry points; each runs scripts/setup.sh first and builds incrementally.
#   make demo    build and run `geods demo` on data/ (gallery in out/demo/index.html)
#   make test    release unit tests, Python tests, then unit tests under ASan+UBSan
#   make bench   side-by-side comparison with the anchor libraries -> docs/PERFORMANCE.md
#   make fuzz    libFuzzer targets of every file reader, FUZZ_SECONDS each
JOBS ?= $(shell nproc)
FUZZ_SECONDS ?= 60
DEMO_OUT ?= out/demo
PYTHON := /usr/bin/python3
# Paths under the checkout are hashed relative to it, so a fresh clone reuses ccache.
export CCACHE_BASEDIR := $(CURDIR)

.PHONY: all setup release demo test bench fuzz clean

all: release

setup:
	@scripts/setup.sh

build/release/build.ninja:
	cmake --preset release
release: setup build/release/build.ninja
	cmake --build build/release -j$(JOBS)

demo: release
	build/release/bin/geods demo --out $(DEMO_OUT)

test: setup build/release/build.ninja
	scripts/run_tests.sh $(JOBS)

bench: release
	@scripts/setup.sh --bench
	$(PYTHON) bench/compare/run.py --out docs/PERFORMANCE.md

build/fuzz/build.ninja:
	cmake --preset fuzz
fuzz:
	@scripts/setup.sh --fuzz
	$(MAKE) build/fuzz/build.ninja
	cmake --build build/fuzz -j$(JOBS)
	fuzz/run.sh build/fuzz $(FUZZ_SECONDS)

clean:
	rm -rf build out
