# tests build fragment. Fragments add their test programs to TEST_BINS
# (built into $(BUILD)/tests/test_*) and anything the suites need to TEST_DEPS.
TEST_BINS ?=
TEST_DEPS ?=
include tests/physics.mk
include tests/health.mk
include tests/level.mk
include tests/kernels.mk
# The build runs in TEST_JOBS lanes (default 2, the CI machine's cores), then
# the suites; `make test-build` alone builds what they need.
TEST_JOBS ?= 2
.PHONY: test-build
test:
	$(MAKE) -j$(TEST_JOBS) test-build
	TEST_JOBS=$(TEST_JOBS) sh tests/run_tests.sh $(BUILD)
test-build: $(TEST_BINS) $(TEST_DEPS)
# The long campaigns beside make test (determinism, fuzz-blobs, fuzz,
# integration-full, cantilever-float, level-all, soak*): tests/CAMPAIGNS.md.
# every build of the determinism matrix (make test runs a slice of it, see
# tests/scripts/test_determinism.sh)
.PHONY: determinism
determinism:
	DET_SET=full BUILD=$(BUILD) sh tests/scripts/test_determinism.sh
