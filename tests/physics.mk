# Physics validation fragment (owner: physics validation). Included from tests/tests.mk.
# The double-precision reference (tests/reference) shares no code with the runtime.
REF_SRC  = tests/reference/snref.c tests/reference/snref_synth.c
REF_HDR  = tests/reference/snref.h tests/reference/snref_synth.h runtime/src/sn_format.h tests/sn_test.h

$(BUILD)/tests/test_reference: tests/test_reference.c $(REF_SRC) $(REF_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -o $@ tests/test_reference.c $(REF_SRC) -lm

TEST_BINS += $(BUILD)/tests/test_reference
