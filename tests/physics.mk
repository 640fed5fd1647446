# Physics validation fragment (owner: physics validation). Included from tests/tests.mk.
# The double-precision reference (tests/reference) shares no code with the runtime.
REF_SRC  = tests/reference/snref.c tests/reference/snref_synth.c
REF_HDR  = tests/reference/snref.h tests/reference/snref_synth.h runtime/src/sn_format.h tests/sn_test.h

$(BUILD)/tests/test_reference: tests/test_reference.c $(REF_SRC) $(REF_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests -o $@ tests/test_reference.c $(REF_SRC) -lm

TEST_BINS += $(BUILD)/tests/test_reference

# Physics tests against the runtime: each built fixed and float (suffix _float).
PHYS_CFLAGS = $(HOST_CFLAGS) $(SN_INC) -Itests -Itests/reference
PHYS_HDRS   = $(REF_HDR) tests/reference/phys_util.h tests/reference/phys_pose.h $(SN_HDRS)
PHYS_TESTS  = cantilever runtime vibration rigid limb longrun

define PHYS_TEST_RULE
$(BUILD)/tests/test_physics_$(1): tests/test_physics_$(1).c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $$(@D)
	$(CC) $(PHYS_CFLAGS) -o $$@ $$< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_physics_$(1)_float: tests/test_physics_$(1).c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $$(@D)
	$(CC) $(PHYS_CFLAGS) -DSN_FLOAT -o $$@ $$< $(REF_SRC) $(SN_LIB_FLOAT) -lm
endef
$(foreach t,$(PHYS_TESTS),$(eval $(call PHYS_TEST_RULE,$(t))))
TEST_BINS += $(foreach t,$(PHYS_TESTS),$(BUILD)/tests/test_physics_$(t) $(BUILD)/tests/test_physics_$(t)_float)

# Beam 4 re-baked with a small time step (h = 1/960 s) for the free-vibration test.
PHYS_EX = $(BUILD)/physics
$(PHYS_EX)/beam4_h960/beam.sinew: $(BUILD)/examples/beam4/beam.sinew
	@mkdir -p $(@D)
	sed 's/^timestep .*/timestep 0.00104166667/' $< > $@
	cp $(BUILD)/examples/beam4/beam.obj $(@D)/beam.obj
$(PHYS_EX)/beam4_h960.blob: $(PHYS_EX)/beam4_h960/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(PHYS_EX)/beam4_h960_float.blob: $(PHYS_EX)/beam4_h960/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
$(PHYS_EX)/beam4_h960_double.blob: $(PHYS_EX)/beam4_h960/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour double --quiet
TEST_DEPS += $(PHYS_EX)/beam4_h960.blob $(PHYS_EX)/beam4_h960_float.blob $(PHYS_EX)/beam4_h960_double.blob

# Beams re-baked with mass damping (alpha = 20/s, about critical for the first
# mode) so the runtime settles on the static equilibrium in a few hundred steps.
$(PHYS_EX)/beam%_damped/beam.sinew: $(BUILD)/examples/beam%/beam.sinew
	@mkdir -p $(@D)
	sed 's/^rayleigh .*/rayleigh 20 0/' $< > $@
	cp $(BUILD)/examples/beam$*/beam.obj $(@D)/beam.obj
$(PHYS_EX)/beam%_damped.blob: $(PHYS_EX)/beam%_damped/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(PHYS_EX)/beam%_damped_float.blob: $(PHYS_EX)/beam%_damped/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(PHYS_EX)/beam%_damped/beam.sinew $(PHYS_EX)/beam4_h960/beam.sinew
TEST_DEPS += $(foreach n,1 2 4,$(PHYS_EX)/beam$(n)_damped.blob $(PHYS_EX)/beam$(n)_damped_float.blob)

# Cow and limb re-baked without gravity: a rigid skeleton motion must then leave
# the shape exactly undeformed (rigid-invariance test).
define PHYS_NOGRAV_RULE
$(PHYS_EX)/$(1)_nograv/asset.sinew: tools/examples/$(1)/$(1).sinew tools/examples/$(1)/$(1).obj
	@mkdir -p $$(@D)
	sed 's/^gravity .*/gravity 0 0 0/' $$< > $$@
	cp tools/examples/$(1)/$(1).obj $$(@D)/$(1).obj
endef
$(foreach a,cow limb,$(eval $(call PHYS_NOGRAV_RULE,$(a))))
$(PHYS_EX)/%_nograv.blob: $(PHYS_EX)/%_nograv/asset.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(PHYS_EX)/%_nograv_float.blob: $(PHYS_EX)/%_nograv/asset.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(PHYS_EX)/%_nograv/asset.sinew
TEST_DEPS += $(foreach a,cow limb,$(PHYS_EX)/$(a)_nograv.blob $(PHYS_EX)/$(a)_nograv_float.blob)
