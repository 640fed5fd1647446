# Health report, limits and rest shape (tests/test_runtime_health.c), fixed and
# float, on cow variants re-baked from the bundled description.
HEALTH_EX = $(BUILD)/health
COW_SRC_DESC = tools/examples/cow/cow.sinew
$(HEALTH_EX)/%/cow.sinew: $(COW_SRC_DESC) tests/health.mk
	@mkdir -p $(@D)
	sed 's|^mesh .*|mesh $(CURDIR)/tools/examples/cow/cow.obj|' $(COW_SRC_DESC) > $@
	case $* in limit) echo 'limit all 0.3' >> $@ ;; farlimit) echo 'limit all 100' >> $@ ;; \
	  rest) echo 'rest_shape modelled' >> $@ ;; esac
$(HEALTH_EX)/cow_%.blob: $(HEALTH_EX)/%/cow.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(HEALTH_EX)/cow_%_float.blob: $(HEALTH_EX)/%/cow.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(HEALTH_EX)/%/cow.sinew
HEALTH_BLOBS = $(foreach v,limit farlimit rest,$(HEALTH_EX)/cow_$(v).blob $(HEALTH_EX)/cow_$(v)_float.blob)

$(BUILD)/tests/health_runtime: tests/test_runtime_health.c $(PHYS_HDRS) $(REF_SRC) $(SN_LIB_FIXED) $(HEALTH_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/health_runtime_float: tests/test_runtime_health.c $(PHYS_HDRS) $(REF_SRC) $(SN_LIB_FLOAT) $(HEALTH_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
# run by tests/scripts/test_health.sh (the binaries take the blob paths)
TEST_DEPS += $(BUILD)/tests/health_runtime $(BUILD)/tests/health_runtime_float $(BUILD)/examples/cow.blob \
             $(BUILD)/examples/cow_float.blob
