# Physics validation fragment (owner: physics validation). Included from tests/tests.mk.
# The double-precision reference (tools/ref/snref.c: host-tool code since
# sinew-bake --static solves with it; tests/reference: the test-only parts)
# shares no code with the runtime.
REF_HDR  = tools/ref/snref.h tests/reference/snref_synth.h runtime/src/sn_format.h tests/sn_test.h
REF_INC  = -Itools/ref
# compiled once (the reference has no fixed/float variant: doubles only) and
# linked into every physics test, instead of 40 compilations of 2,400 lines
# (snref.o: the host tool's object, tools/tools.mk, the same source and flags)
REF_SRC  = $(BUILD)/tools/ref/snref.o $(BUILD)/ref/snref_synth.o
$(BUILD)/ref/snref_synth.o: tests/reference/snref_synth.c $(REF_HDR)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(REF_INC) -c -o $@ $<

$(BUILD)/tests/test_reference: tests/test_reference.c $(REF_SRC) $(REF_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests $(REF_INC) -o $@ tests/test_reference.c $(REF_SRC) -lm

TEST_BINS += $(BUILD)/tests/test_reference

# Rig controls and forces in the reference (issue 10): no runtime; rigs
# written by the tests' own writer (tests/rig_common.h) into a synthetic box
# and the examples' limb.
$(BUILD)/tests/test_rig_reference: tests/test_rig_reference.c tests/rig_common.h $(REF_SRC) $(REF_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itests $(REF_INC) -o $@ tests/test_rig_reference.c $(REF_SRC) -lm
TEST_BINS += $(BUILD)/tests/test_rig_reference


# make soak: the held-twist energy check of test_reference (limb twisted 170
# degrees, damping off) over 600 s instead of make test's 60 s.
.PHONY: soak
soak: $(BUILD)/tests/test_reference $(BUILD)/examples/limb_double.blob
	SN_SOAK_SECONDS=$${SN_SOAK_SECONDS:-600} BUILD=$(BUILD) $(BUILD)/tests/test_reference --soak

# Physics tests against the runtime: each built fixed and float (suffix _float).
PHYS_CFLAGS = $(HOST_CFLAGS) $(SN_INC) -Itests -Itests/reference $(REF_INC)
PHYS_HDRS   = $(REF_HDR) tests/reference/phys_util.h tests/reference/phys_pose.h $(SN_HDRS)
PHYS_TESTS  = cantilever runtime vibration rigid limb longrun teleport soak segment

define PHYS_TEST_RULE
$(BUILD)/tests/test_physics_$(1): tests/test_physics_$(1).c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $$(@D)
	$(CC) $(PHYS_CFLAGS) -o $$@ $$< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_physics_$(1)_float: tests/test_physics_$(1).c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $$(@D)
	$(CC) $(PHYS_CFLAGS) -DSN_FLOAT -o $$@ $$< $(REF_SRC) $(SN_LIB_FLOAT) -lm
endef
$(foreach t,$(PHYS_TESTS),$(eval $(call PHYS_TEST_RULE,$(t))))

# Crease self-collision in the runtime (seed 003 §3.4; tests/test_runtime_crease.c):
# the physics tests' helpers and the runtime's internal headers
# and the host tool's inside test (tools/sb_mesh.c)
CREASE_TSRC = tools/sb_mesh.c tools/sb_util.c
$(BUILD)/tests/test_runtime_crease: tests/test_runtime_crease.c $(REF_SRC) $(CREASE_TSRC) $(PHYS_HDRS) tools/sb.h $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -Itools -o $@ $< $(REF_SRC) $(CREASE_TSRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_crease_float: tests/test_runtime_crease.c $(REF_SRC) $(CREASE_TSRC) $(PHYS_HDRS) tools/sb.h $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -Itools -DSN_FLOAT -o $@ $< $(REF_SRC) $(CREASE_TSRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_crease $(BUILD)/tests/test_runtime_crease_float

# Blended local linearization (SN_MODE_BLENDED, seed 000 §4.5) against SNREF_BLENDED over clips
BLEND_TSRC = ports/common/sn_clip.c ports/common/sn_clip_pose.c
$(BUILD)/tests/test_physics_blended: tests/test_physics_blended.c $(REF_SRC) $(BLEND_TSRC) ports/common/sn_clip.h $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iports/common -o $@ $< $(REF_SRC) $(BLEND_TSRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_physics_blended_float: tests/test_physics_blended.c $(REF_SRC) $(BLEND_TSRC) ports/common/sn_clip.h $(PHYS_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iports/common -DSN_FLOAT -o $@ $< $(REF_SRC) $(BLEND_TSRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_physics_blended $(BUILD)/tests/test_physics_blended_float
TEST_BINS += $(foreach t,$(PHYS_TESTS),$(BUILD)/tests/test_physics_$(t) $(BUILD)/tests/test_physics_$(t)_float)

# make soak-adversarial: test_physics_soak (issue 16 item 6) run long, fixed and
# float: SN_SOAK_STEPS abuse steps per asset (make test runs a short slice),
# a recovery check every SN_SOAK_ROUND steps.
.PHONY: soak-adversarial
soak-adversarial: $(BUILD)/tests/test_physics_soak $(BUILD)/tests/test_physics_soak_float $(EX)/cow.blob $(EX)/cow_float.blob $(EX)/beast.blob $(EX)/beast_float.blob
	SN_SOAK_STEPS=$${SN_SOAK_STEPS:-200000} SN_SOAK_ROUND=$${SN_SOAK_ROUND:-10000} BUILD=$(BUILD) $(BUILD)/tests/test_physics_soak
	SN_SOAK_STEPS=$${SN_SOAK_STEPS:-200000} SN_SOAK_ROUND=$${SN_SOAK_ROUND:-10000} BUILD=$(BUILD) $(BUILD)/tests/test_physics_soak_float

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

# make cantilever-float: the float cantilever at every size (make test runs beam1;
# the fixed build runs every size in make test)
.PHONY: cantilever-float
cantilever-float: $(BUILD)/tests/test_physics_cantilever_float $(foreach n,1 2 4,$(PHYS_EX)/beam$(n)_damped_float.blob $(EX)/beam$(n)_double.blob $(EX)/beam$(n)_float.blob)
	BUILD=$(BUILD) $(BUILD)/tests/test_physics_cantilever_float --all

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

# Head-turn acceptance (issue 9 item 2): neck turned 90 degrees about its own
# axis on the cow and the beast (blobs from tools/tools.mk, and without gravity).
$(eval $(call PHYS_TEST_RULE,headturn))
TEST_BINS += $(BUILD)/tests/test_physics_headturn $(BUILD)/tests/test_physics_headturn_float
$(eval $(call PHYS_NOGRAV_RULE,beast))
TEST_DEPS += $(PHYS_EX)/beast_nograv.blob $(PHYS_EX)/beast_nograv_float.blob

# Held poses (issue 9 item 1): limb, cow and beast, joints ramped to 0..180
# degrees and held, with the asset's damping (examples blobs) and re-baked
# with Rayleigh 0 0 into $(HELD_DIR). `make soak`: the full sweep (long).
$(eval $(call PHYS_TEST_RULE,held))
TEST_BINS += $(BUILD)/tests/test_physics_held $(BUILD)/tests/test_physics_held_float
HELD_DIR    = $(PHYS_EX)/held
HELD_ASSETS = cow limb $(if $(wildcard tools/examples/beast/beast.sinew),beast)
define HELD_UNDAMPED_RULE
$(HELD_DIR)/$(1)_undamped/asset.sinew: tools/examples/$(1)/$(1).sinew $(wildcard tools/examples/$(1)/*.obj)
	@mkdir -p $$(@D)
	sed '/^[[:space:]]*rayleigh[[:space:]]/d' $$< > $$@
	echo 'rayleigh 0 0' >> $$@
	for f in tools/examples/$(1)/*.obj; do ln -sf "$$(CURDIR)/$$$$f" $$(@D)/; done
endef
$(foreach a,$(HELD_ASSETS),$(eval $(call HELD_UNDAMPED_RULE,$(a))))
$(HELD_DIR)/%_undamped.blob: $(HELD_DIR)/%_undamped/asset.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(HELD_DIR)/%_undamped_float.blob: $(HELD_DIR)/%_undamped/asset.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(HELD_DIR)/%_undamped/asset.sinew
HELD_BLOBS = $(foreach a,$(HELD_ASSETS),$(HELD_DIR)/$(a)_undamped.blob $(HELD_DIR)/$(a)_undamped_float.blob \
                 $(EX)/$(a).blob $(EX)/$(a)_float.blob $(EX)/$(a)_double.blob)
TEST_DEPS += $(HELD_BLOBS)
# soak has its recipe above; this only adds a prerequisite.
.PHONY: soak soak-held
soak: soak-held
soak-held: $(BUILD)/tests/test_physics_held $(BUILD)/tests/test_physics_held_float $(HELD_BLOBS)
	BUILD=$(BUILD) $(BUILD)/tests/test_physics_held soak
	BUILD=$(BUILD) $(BUILD)/tests/test_physics_held_float soak

# Rigs in the runtime vs the reference (issue 10), fixed and float, on the
# limb with the tests' rigs (and the limb without gravity, also as float64).
RIG_RT_DEPS = tests/test_rig_runtime.c tests/rig_common.h $(REF_SRC) $(PHYS_HDRS)
$(BUILD)/tests/test_rig_runtime: $(RIG_RT_DEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_rig_runtime_float: $(RIG_RT_DEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
$(PHYS_EX)/%_nograv_double.blob: $(PHYS_EX)/%_nograv/asset.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour double --quiet
TEST_BINS += $(BUILD)/tests/test_rig_runtime $(BUILD)/tests/test_rig_runtime_float
# tau white box: includes runtime/src/sn_rig.c (its static tau) and links the rest of the library
$(BUILD)/tests/test_rig_tau: tests/test_rig_tau.c runtime/src/sn_rig.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_rig_tau_float: tests/test_rig_tau.c runtime/src/sn_rig.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_rig_tau $(BUILD)/tests/test_rig_tau_float
TEST_DEPS += $(PHYS_EX)/limb_nograv_double.blob

# The limb without its rigs (control and rig lines dropped): test_physics_limb
# measures the elastic model itself; its pose-driven biceps would otherwise
# switch on as the elbow bends (the rig is measured by test_rig_runtime).
$(PHYS_EX)/limb_norig/limb.sinew: tools/examples/limb/limb.sinew tests/physics.mk
	@mkdir -p $(@D)
	sed -e 's|^mesh .*|mesh $(CURDIR)/tools/examples/limb/limb.obj|' -e '/^control /d' -e '/^rig /d' -e '/^tau /d' $< > $@
$(PHYS_EX)/limb_norig.blob: $(PHYS_EX)/limb_norig/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(PHYS_EX)/limb_norig_float.blob: $(PHYS_EX)/limb_norig/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
$(PHYS_EX)/limb_norig_double.blob: $(PHYS_EX)/limb_norig/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour double --quiet
TEST_DEPS += $(PHYS_EX)/limb_norig.blob $(PHYS_EX)/limb_norig_float.blob $(PHYS_EX)/limb_norig_double.blob

# External forces and impulses (issue 14): distribution, wrench, response vs
# the reference; white box (sn_forces_rhs), fixed and float.
FORCE_RT_DEPS = tests/test_runtime_force.c $(REF_SRC) $(PHYS_HDRS)
$(BUILD)/tests/test_runtime_force: $(FORCE_RT_DEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_force_float: $(FORCE_RT_DEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_force $(BUILD)/tests/test_runtime_force_float

# Nonlinear St. Venant-Kirchhoff reference (issue 13 items 5-6,
# tests/reference/NONLINEAR.md): bakes the limb and the cow with the tool
# library itself and compares global linear, warped and nonlinear solutions.
# (snref: the host tool's object, as REF_SRC, not a third compile of it)
NL_SRC = tests/reference/nlref.c $(BUILD)/tools/ref/snref.o ports/desktop/raster.c ports/desktop/png.c
NL_HDR = tests/reference/nlref.h tools/ref/snref.h tools/sb.h tests/sn_test.h ports/desktop/raster.h ports/desktop/png.h
$(BUILD)/tests/test_nonlinear: tests/test_nonlinear.c $(NL_SRC) $(NL_HDR) $(TOOLS_LIB) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests -Itests/reference -Itools -Itools/ref -Iruntime/include -Iruntime/src -Iports/desktop -o $@ tests/test_nonlinear.c $(NL_SRC) $(TOOLS_LIB) $(SN_LIB_FIXED) -lm
TEST_BINS += $(BUILD)/tests/test_nonlinear

# make nonlinear-figures: the same tables with a longer dynamic run, the limb
# also at half the cell, and $(BUILD)/nonlinear/elbow120.png (nonlinear |
# warped | global linear at the 120-degree elbow).
.PHONY: nonlinear-figures
nonlinear-figures: $(BUILD)/tests/test_nonlinear
	BUILD=$(BUILD) $(BUILD)/tests/test_nonlinear --figures

# Preconditioner study (issue 15 item 3; NUMERICS.md "Preconditioners
# measured"): double precision, the reference stepping the examples' clips,
# every step's system solved by each candidate. Not part of make test.
$(BUILD)/tests/precond_study: tests/precond_study.c tests/reference/ref_clips.h $(REF_SRC) $(PHYS_HDRS) ports/common/sn_clip.c ports/common/sn_clip_pose.c ports/common/sn_clip.h $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iports/common -o $@ $< $(REF_SRC) ports/common/sn_clip.c ports/common/sn_clip_pose.c $(SN_LIB_FIXED) -lm
# The runtime-vs-reference table at 4, 8, 16, 32 iterations and each asset's
# default (make test runs the default count only, where every check is).
.PHONY: accuracy-sweep
accuracy-sweep: $(BUILD)/tests/test_physics_runtime $(BUILD)/tests/test_physics_runtime_float
	SN_ACCURACY_SWEEP=1 BUILD=$(BUILD) $(BUILD)/tests/test_physics_runtime
	SN_ACCURACY_SWEEP=1 BUILD=$(BUILD) $(BUILD)/tests/test_physics_runtime_float
.PHONY: precond-study
precond-study: $(BUILD)/tests/precond_study $(EX)/cow.blob $(EX)/limb.blob $(EX)/beast.blob
	$(BUILD)/tests/precond_study $(EX)/cow.blob tools/examples/cow/trot.clip tools/examples/cow/head_turn.clip -every 1
	$(BUILD)/tests/precond_study $(EX)/limb.blob tools/examples/limb/flex.clip -every 1
	$(BUILD)/tests/precond_study $(EX)/beast.blob tools/examples/beast/walk.clip tools/examples/beast/head_turn.clip -every 2

# Stiffness storage study (issue 15 item 4; NUMERICS.md "Narrower stiffness
# storage, measured"): the float64 blob's cell matrices re-quantized, the
# reference's 600-step error against float64. Not part of make test.
$(BUILD)/tests/quant_study: tests/quant_study.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
.PHONY: quant-study
quant-study: $(BUILD)/tests/quant_study $(EX)/cow.blob $(EX)/cow_double.blob $(EX)/limb.blob $(EX)/limb_double.blob
	$(BUILD)/tests/quant_study $(EX)/cow.blob $(EX)/cow_double.blob cow
	$(BUILD)/tests/quant_study $(EX)/limb.blob $(EX)/limb_double.blob limb

# Position constraints and colliders (issue 12 items 1 and 3): rows hold,
# the double reference's constrained solve, drops, ground and sphere,
# overflow, API; white box (sn_constraint.h), fixed and float.
CONS_RT_DEPS = tests/test_runtime_constraint.c $(REF_SRC) $(PHYS_HDRS) ports/common/sn_clip.c ports/common/sn_clip_pose.c ports/common/sn_clip.h
CONS_RT_SRCS = $(REF_SRC) ports/common/sn_clip.c ports/common/sn_clip_pose.c
$(BUILD)/tests/test_runtime_constraint: $(CONS_RT_DEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -Iports/common -o $@ $< $(CONS_RT_SRCS) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_constraint_float: $(CONS_RT_DEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -Iports/common -DSN_FLOAT -o $@ $< $(CONS_RT_SRCS) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_constraint $(BUILD)/tests/test_runtime_constraint_float
# sn_contact_rows' per-use fallback (a saturated prediction): the runtime built
# with -DSN_CT_PER_USE must give the fast path's contact hashes. Only
# sn_contact.c reads the macro: it alone is rebuilt with it (the library's
# flags), linked ahead of the library, whose sn_contact.o is then not pulled
# (as tests/level.mk's fold build), instead of the whole runtime per test
CT_PU_SRC = ports/cross/sn_det.c ports/common/sn_clip.c ports/common/sn_clip_pose.c
CT_PU_DEPS = tests/test_contact_per_use.c $(CT_PU_SRC) ports/cross/sn_det.h ports/common/sn_clip.h $(SN_TEST_HDRS)
CT_PU_OBJ = $(BUILD)/tests/per_use
$(CT_PU_OBJ)/sn_contact.o: runtime/src/sn_contact.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) $(SN_INC) -DSN_CT_PER_USE -c $< -o $@
$(CT_PU_OBJ)/sn_contact_float.o: runtime/src/sn_contact.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) $(SN_INC) -DSN_FLOAT -DSN_CT_PER_USE -c $< -o $@
$(BUILD)/tests/test_contact_per_use: $(CT_PU_DEPS) $(CT_PU_OBJ)/sn_contact.o $(SN_LIB_FIXED) $(EX)/cow.blob
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) $(SN_SIMD_FLAGS) -DSN_CT_PER_USE -Iports/cross -Iports/common -o $@ $< $(CT_PU_SRC) \
	    $(CT_PU_OBJ)/sn_contact.o $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_contact_per_use_float: $(CT_PU_DEPS) $(CT_PU_OBJ)/sn_contact_float.o $(SN_LIB_FLOAT) $(EX)/cow_float.blob
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) $(SN_SIMD_FLAGS) -DSN_FLOAT -DSN_CT_PER_USE -Iports/cross -Iports/common -o $@ $< $(CT_PU_SRC) \
	    $(CT_PU_OBJ)/sn_contact_float.o $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_contact_per_use $(BUILD)/tests/test_contact_per_use_float
# the cow with 8 contacts a step: the contact maximum overflows (test_runtime_constraint)
$(PHYS_EX)/cow_c8/cow.sinew: tools/examples/cow/cow.sinew tests/physics.mk
	@mkdir -p $(@D)
	sed -e 's|^mesh .*|mesh $(CURDIR)/tools/examples/cow/cow.obj|' -e 's|^colliders .*|colliders 4 8|' $< > $@
$(PHYS_EX)/cow_c8.blob: $(PHYS_EX)/cow_c8/cow.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(PHYS_EX)/cow_c8_float.blob: $(PHYS_EX)/cow_c8/cow.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
TEST_DEPS += $(PHYS_EX)/cow_c8.blob $(PHYS_EX)/cow_c8_float.blob $(EX)/beast.blob $(EX)/beast_float.blob

# IC(0) iteration counts (issue 15 item 3, tools/DESCRIPTION.md "Preconditioner"):
# the whole-clip criterion of runtime/SOLVER_STUDY.md §1 on the examples'
# ICHOL blobs against block Jacobi at today's counts (cow 10, limb 16, beast
# 10; the same descriptions baked with 'precond jacobi'). Not part of make test.
$(BUILD)/tests/ichol_count: tests/ichol_count.c tests/reference/ref_clips.h $(REF_SRC) $(PHYS_HDRS) ports/common/sn_clip.c ports/common/sn_clip_pose.c ports/common/sn_clip.h $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iports/common -o $@ $< $(REF_SRC) ports/common/sn_clip.c ports/common/sn_clip_pose.c $(SN_LIB_FIXED) -lm
define JACOBI_BLOB_RULE
$(EX)/$(1)_jacobi.blob: tools/examples/$(1)/$(1).sinew $(BAKE)
	@mkdir -p $(EX)/$(1)_jacobi
	sed 's|^mesh \(.*\)|mesh $(CURDIR)/tools/examples/$(1)/\1|' $$< > $(EX)/$(1)_jacobi/$(1).sinew
	echo "precond jacobi" >> $(EX)/$(1)_jacobi/$(1).sinew
	$(BAKE) $(EX)/$(1)_jacobi/$(1).sinew -o $$@ --quiet
endef
$(foreach a,cow limb beast,$(eval $(call JACOBI_BLOB_RULE,$(a))))
.PHONY: ichol-counts
ichol-counts: $(BUILD)/tests/ichol_count $(EX)/cow.blob $(EX)/limb.blob $(EX)/beast.blob $(EX)/cow_jacobi.blob $(EX)/limb_jacobi.blob $(EX)/beast_jacobi.blob
	$(BUILD)/tests/ichol_count $(EX)/cow_jacobi.blob $(EX)/cow.blob 10 tools/examples/cow/trot.clip tools/examples/cow/head_turn.clip
	$(BUILD)/tests/ichol_count $(EX)/limb_jacobi.blob $(EX)/limb.blob 16 tools/examples/limb/flex.clip
	$(BUILD)/tests/ichol_count $(EX)/beast_jacobi.blob $(EX)/beast.blob 10 tools/examples/beast/walk.clip tools/examples/beast/head_turn.clip

# The IC(0) apply against a double solve with the same factor (issue 15 item 3):
# runtime internals (sn_precond) and the reference's decoded ICHOL.
$(BUILD)/tests/test_runtime_precond: tests/test_runtime_precond.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED) $(EX)/cow.blob $(EX)/beast.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_precond_float: tests/test_runtime_precond.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT) $(EX)/cow_float.blob $(EX)/beast_float.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_precond $(BUILD)/tests/test_runtime_precond_float

# The step's frames (sn_pose.c: pair cache and frame memo) against each frame
# computed alone, bit for bit: runtime internals.
$(BUILD)/tests/test_runtime_frames: tests/test_runtime_frames.c $(PHYS_HDRS) $(SN_LIB_FIXED) $(EX)/cow.blob $(EX)/beast.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_frames_float: tests/test_runtime_frames.c $(PHYS_HDRS) $(SN_LIB_FLOAT) $(EX)/cow_float.blob $(EX)/beast_float.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_frames $(BUILD)/tests/test_runtime_frames_float

# The embedded surface's output (sn_embed.c: the plain lattice's own loop)
# against the general path bit for bit and the double embedding.
$(BUILD)/tests/test_runtime_surface: tests/test_runtime_surface.c $(PHYS_HDRS) $(SN_LIB_FIXED) $(EX)/cow.blob $(EX)/beast.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_surface_float: tests/test_runtime_surface.c $(PHYS_HDRS) $(SN_LIB_FLOAT) $(EX)/cow_float.blob $(EX)/beast_float.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_surface $(BUILD)/tests/test_runtime_surface_float

# make seg-study (issue 15): the segment meshes' gap through the cow's trot for
# blobs given in SEG_BLOBS (default: the cow, fixed and float); tests/scripts/seg_study.sh
# bakes the sweep-count variants.
$(BUILD)/tests/seg_study: tests/seg_study.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/seg_study_float: tests/seg_study.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
.PHONY: seg-study
seg-study: $(BUILD)/tests/seg_study $(BUILD)/tests/seg_study_float $(BUILD)/sinew-bake
	BUILD=$(BUILD) sh tests/scripts/seg_study.sh
