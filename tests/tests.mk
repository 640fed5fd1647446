# tests build fragment. Fragments add their test programs to TEST_BINS
# (built into $(BUILD)/tests/test_*) and anything the suites need to TEST_DEPS.
TEST_BINS ?=
TEST_DEPS ?=
include tests/physics.mk
include tests/health.mk
include tests/level.mk
test: $(TEST_BINS) $(TEST_DEPS)
	sh tests/run_tests.sh $(BUILD)
