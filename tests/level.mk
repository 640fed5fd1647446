# Level of detail (runtime/src/sn_level.c, tests/test_runtime_level.c), fixed
# and float, on the cow and the beast re-baked from their descriptions with
# 'levels 2'; run by tests/scripts/test_level.sh (the binaries take the blob paths).
LEVEL_EX = $(BUILD)/level
define LEVEL_DESC_RULE
$(LEVEL_EX)/$(1)/lod.sinew: tools/examples/$(1)/$(1).sinew tests/level.mk
	@mkdir -p $$(@D)
	sed 's|^mesh \(.*\)|mesh $(CURDIR)/tools/examples/$(1)/\1|' $$< > $$@
	echo 'levels 2' >> $$@
endef
$(foreach c,cow beast,$(eval $(call LEVEL_DESC_RULE,$(c))))
$(LEVEL_EX)/%_lod.blob: $(LEVEL_EX)/%/lod.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_lod_float.blob: $(LEVEL_EX)/%/lod.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(LEVEL_EX)/%/lod.sinew
LEVEL_BLOBS = $(foreach c,cow beast,$(LEVEL_EX)/$(c)_lod.blob $(LEVEL_EX)/$(c)_lod_float.blob)

# The cut level (runtime/LEVELS.md §2 "The cut level", tests/test_runtime_cut.c): the same
# two-level descriptions with 'levels 2 cut', their constraint and collider slots kept (the
# rows follow the cut field: tests/test_runtime_cut_rows.c).
$(LEVEL_EX)/%/cut.sinew: $(LEVEL_EX)/%/lod.sinew tests/level.mk
	sed -e 's/^levels 2$$/levels 2 cut/' $< > $@
$(LEVEL_EX)/%_cut.blob: $(LEVEL_EX)/%/cut.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_cut_float.blob: $(LEVEL_EX)/%/cut.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(LEVEL_EX)/%/cut.sinew
# the limb's cut level: the fuzzers' seed (tests/fuzz/fuzz.mk) and a small blob for hostile runs,
# with constraint and collider slots (the rows' code and the CONSTRAINTS record under the fuzzers)
$(LEVEL_EX)/limb/cut.sinew: tools/examples/limb/limb.sinew tests/level.mk
	@mkdir -p $(@D)
	sed -e 's|^mesh \(.*\)|mesh $(CURDIR)/tools/examples/limb/\1|' $< > $@
	printf 'constraints 4\ncolliders 2 8\nlevels 2 cut\ndetails 8 0.03 0.01\n' >> $@
# details on the cut level (runtime/LEVELS.md §3 "Details on the cut level"; format 6.5): the cut
# descriptions with 'details 50 0.03 0.01' (the study's A_max and runtime thresholds)
$(LEVEL_EX)/%/details.sinew: $(LEVEL_EX)/%/cut.sinew tests/level.mk
	cp $< $@ && echo 'details 50 0.03 0.01' >> $@
$(LEVEL_EX)/%_details.blob: $(LEVEL_EX)/%/details.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_details_float.blob: $(LEVEL_EX)/%/details.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(LEVEL_EX)/%/details.sinew
# every detail active (stage 2's correctness run): A_max clamped to nD by the bake
$(LEVEL_EX)/%/dall.sinew: $(LEVEL_EX)/%/cut.sinew tests/level.mk
	cp $< $@ && echo 'details 65535 0.03 0.01' >> $@
$(LEVEL_EX)/%_dall.blob: $(LEVEL_EX)/%/dall.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_dall_float.blob: $(LEVEL_EX)/%/dall.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(LEVEL_EX)/%/dall.sinew
DSTEP_BLOBS = $(LEVEL_EX)/cow_lod.blob $(LEVEL_EX)/cow_lod_float.blob $(LEVEL_EX)/cow_cut.blob $(LEVEL_EX)/cow_cut_float.blob \
              $(LEVEL_EX)/cow_details.blob $(LEVEL_EX)/cow_details_float.blob $(LEVEL_EX)/cow_dall.blob $(LEVEL_EX)/cow_dall_float.blob
# the details stepped against level 1 (tests/test_runtime_dstep.c; LEVELS.md §3 stage 2)
$(BUILD)/tests/test_runtime_dstep: tests/test_runtime_dstep.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FIXED) $(DSTEP_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_dstep_float: tests/test_runtime_dstep.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FLOAT) $(DSTEP_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_dstep $(BUILD)/tests/test_runtime_dstep_float
# the same on the beast (its elbow and neck, LEVELS.md §3's columns): not in make test (12-17 s of CPU
# for the four runs, 6 s more for its four details bakes; tests/CAMPAIGNS.md)
DSTEP_BEAST_BLOBS = $(foreach k,lod cut details dall,$(LEVEL_EX)/beast_$(k).blob $(LEVEL_EX)/beast_$(k)_float.blob)
.PHONY: dstep-beast
dstep-beast: $(BUILD)/tests/test_runtime_dstep $(BUILD)/tests/test_runtime_dstep_float $(DSTEP_BEAST_BLOBS)
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_dstep beast elbow_l y 90
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_dstep_float beast elbow_l y 90
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_dstep beast neck y 60
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_dstep_float beast neck y 60
DETAIL_BLOBS = $(LEVEL_EX)/limb_cut.blob $(LEVEL_EX)/limb_cut_float.blob $(LEVEL_EX)/cow_cut.blob $(LEVEL_EX)/cow_cut_float.blob \
               $(LEVEL_EX)/cow_details.blob $(LEVEL_EX)/cow_details_float.blob
# the details' sections under the validator (crafted changes) and beside the cut level (tests/test_runtime_details.c)
$(BUILD)/tests/test_runtime_details: tests/test_runtime_details.c $(SN_TEST_HDRS) $(SN_LIB_FIXED) $(DETAIL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_details_float: tests/test_runtime_details.c $(SN_TEST_HDRS) $(SN_LIB_FLOAT) $(DETAIL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_details $(BUILD)/tests/test_runtime_details_float
# the crease limb's cut level (crease rows on the cut level: tests/test_runtime_cut_rows.c)
$(LEVEL_EX)/limb_crease/cut.sinew: tools/examples/limb/limb_crease.sinew tests/level.mk
	@mkdir -p $(@D)
	sed -e 's|^mesh \(.*\)|mesh $(CURDIR)/tools/examples/limb/\1|' $< > $@
	echo 'levels 2 cut' >> $@
$(LEVEL_EX)/%_cut_double.blob: $(LEVEL_EX)/%/cut.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour double --quiet
CUT_BLOBS = $(foreach c,cow beast,$(LEVEL_EX)/$(c)_cut.blob $(LEVEL_EX)/$(c)_cut_float.blob)
# the cut level settled against the double-precision static reference (tests/test_physics_cut.c)
$(BUILD)/tests/test_physics_cut: tests/test_physics_cut.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED) $(CUT_BLOBS) $(LEVEL_EX)/cow_cut_double.blob $(LEVEL_EX)/beast_cut_double.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_physics_cut_float: tests/test_physics_cut.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT) $(CUT_BLOBS) $(LEVEL_EX)/cow_cut_double.blob $(LEVEL_EX)/beast_cut_double.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_physics_cut $(BUILD)/tests/test_physics_cut_float
$(BUILD)/tests/cut_runtime: tests/test_runtime_cut.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FIXED) $(CUT_BLOBS) $(LEVEL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/cut_runtime_float: tests/test_runtime_cut.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FLOAT) $(CUT_BLOBS) $(LEVEL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_DEPS += $(BUILD)/tests/cut_runtime $(BUILD)/tests/cut_runtime_float
# constraint, contact and crease rows on the cut level (tests/test_runtime_cut_rows.c; run by tests/scripts/test_level.sh)
$(LEVEL_EX)/%_crease_cut.blob: $(LEVEL_EX)/%_crease/cut.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_crease_cut_float.blob: $(LEVEL_EX)/%_crease/cut.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
CUT_ROWS_BLOBS = $(CUT_BLOBS) $(LEVEL_BLOBS) $(LEVEL_EX)/limb_crease_cut.blob $(LEVEL_EX)/limb_crease_cut_float.blob
$(BUILD)/tests/cut_rows: tests/test_runtime_cut_rows.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FIXED) $(CUT_ROWS_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -o $@ $< $(REF_SRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/cut_rows_float: tests/test_runtime_cut_rows.c $(REF_SRC) $(PHYS_HDRS) $(SN_LIB_FLOAT) $(CUT_ROWS_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -o $@ $< $(REF_SRC) $(SN_LIB_FLOAT) -lm
# the runtime with every crease pair's skeleton entries folded into its target (the limb's pairs need no fold):
# sn_crease.c alone rebuilt with -DSN_CR_FOLD_ALL, linked ahead of the library (whose sn_crease.o is then not pulled)
$(BUILD)/tests/fold/sn_crease.o: runtime/src/sn_crease.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) $(SN_INC) -DSN_CR_FOLD_ALL -c $< -o $@
$(BUILD)/tests/fold/sn_crease_float.o: runtime/src/sn_crease.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) $(SN_INC) -DSN_FLOAT -DSN_CR_FOLD_ALL -c $< -o $@
$(BUILD)/tests/cut_rows_fold: tests/test_runtime_cut_rows.c $(REF_SRC) $(PHYS_HDRS) $(BUILD)/tests/fold/sn_crease.o $(SN_LIB_FIXED) $(LEVEL_EX)/limb_crease_cut.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_CR_FOLD_ALL -o $@ $< $(REF_SRC) $(BUILD)/tests/fold/sn_crease.o $(SN_LIB_FIXED) -lm
$(BUILD)/tests/cut_rows_fold_float: tests/test_runtime_cut_rows.c $(REF_SRC) $(PHYS_HDRS) $(BUILD)/tests/fold/sn_crease_float.o $(SN_LIB_FLOAT) $(LEVEL_EX)/limb_crease_cut_float.blob
	@mkdir -p $(@D)
	$(CC) $(PHYS_CFLAGS) -Iruntime/src -DSN_FLOAT -DSN_CR_FOLD_ALL -o $@ $< $(REF_SRC) $(BUILD)/tests/fold/sn_crease_float.o $(SN_LIB_FLOAT) -lm
TEST_DEPS += $(BUILD)/tests/cut_rows $(BUILD)/tests/cut_rows_float $(BUILD)/tests/cut_rows_fold $(BUILD)/tests/cut_rows_fold_float

# Adaptation (runtime/src/sn_adapt.c, tests/test_runtime_adapt.c): the same
# two-level blobs with 'adapt REFINE COARSEN MAX_ACTIVE' (level-0 cells); the
# test patches the record for its other settings.
ADAPT_LINE = adapt 0.03 0.01 250
$(LEVEL_EX)/%/adapt.sinew: $(LEVEL_EX)/%/lod.sinew tests/level.mk
	cp $< $@
	echo '$(ADAPT_LINE)' >> $@
$(LEVEL_EX)/%_adapt.blob: $(LEVEL_EX)/%/adapt.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(LEVEL_EX)/%_adapt_float.blob: $(LEVEL_EX)/%/adapt.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
.PRECIOUS: $(LEVEL_EX)/%/adapt.sinew
ADAPT_BLOBS = $(foreach c,cow beast,$(LEVEL_EX)/$(c)_adapt.blob $(LEVEL_EX)/$(c)_adapt_float.blob)

$(BUILD)/tests/adapt_runtime: tests/test_runtime_adapt.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FIXED) $(ADAPT_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/adapt_runtime_float: tests/test_runtime_adapt.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FLOAT) $(ADAPT_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_DEPS += $(BUILD)/tests/adapt_runtime $(BUILD)/tests/adapt_runtime_float
# adaptation's scales on a hostile level map (every detail vertex in one cell,
# masses at the limit): the ASan + UBSan runtime objects of the blob fuzzer
$(BUILD)/tests/test_runtime_adapt_hostile: tests/fuzz/adapt_hostile.c $(SN_TEST_HDRS) $(SN_FUZZ_OBJS_nock) $(LEVEL_EX)/cow_adapt.blob
	@mkdir -p $(@D)
	$(CC) $(SN_FUZZ_CFLAGS) -DSN_VALIDATE_NO_CHECKSUM -Itests -o $@ $< $(SN_FUZZ_OBJS_nock) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_adapt_hostile

$(BUILD)/tests/level_runtime: tests/test_runtime_level.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FIXED) $(LEVEL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/level_runtime_float: tests/test_runtime_level.c $(SN_TEST_HDRS) tests/level_util.h $(SN_LIB_FLOAT) $(LEVEL_BLOBS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
TEST_DEPS += $(BUILD)/tests/level_runtime $(BUILD)/tests/level_runtime_float $(BUILD)/examples/cow.blob \
             $(BUILD)/examples/cow_float.blob $(BUILD)/examples/beast.blob $(BUILD)/examples/beast_float.blob

# tests/scripts/test_level.sh with the float cow's adaptation run too (make
# test runs the float beast's, which also overflows A_max)
.PHONY: level-all
level-all: test-build
	LEVEL_ALL=1 BUILD=$(BUILD) sh tests/scripts/test_level.sh

# The hostile-blob fuzzer over a blob with LEVEL_BLOB and ADAPT (both levels
# stepped, adaptation on level 1, then blended): part of `make fuzz-blobs`,
# not of make test (about 85 s of CPU per 100 flips a section on a two-level
# limb; the cow's pair is larger).
.PHONY: fuzz-adapt
fuzz-adapt: $(BUILD)/tests/test_runtime_fuzz $(BUILD)/tests/test_runtime_fuzz_float $(LEVEL_EX)/cow_adapt.blob $(LEVEL_EX)/cow_adapt_float.blob
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_fuzz $(LEVEL_EX)/cow_adapt.blob --per-section $(FUZZ_BLOB_PER_SECTION) --edge 16
	BUILD=$(BUILD) $(BUILD)/tests/test_runtime_fuzz_float $(LEVEL_EX)/cow_adapt_float.blob --per-section $(FUZZ_BLOB_PER_SECTION) --edge 16
fuzz-blobs: fuzz-adapt

# The shared workspace (sn_instance_init_shared, sn_step_with; issue 15):
# shared vs own scratch on the cow's trot (contact, blended), the crease limb,
# the two-level and adaptation cows, the humanoid (trot, contact, blended); poison, interleaving, guards, refusals.
WS_TSRC = ports/cross/sn_det.c ports/common/sn_clip.c ports/common/sn_clip_pose.c
WS_TDEPS = $(WS_TSRC) ports/cross/sn_det.h ports/common/sn_clip.h $(SN_TEST_HDRS)
WS_BLOBS = $(EX)/cow.blob $(EX)/cow_float.blob $(EX)/limb_crease.blob $(EX)/limb_crease_float.blob \
           $(LEVEL_EX)/cow_lod.blob $(LEVEL_EX)/cow_lod_float.blob $(LEVEL_EX)/cow_adapt.blob $(LEVEL_EX)/cow_adapt_float.blob \
           $(EX)/beast.blob $(EX)/beast_float.blob
$(BUILD)/tests/test_runtime_workspace: tests/test_runtime_workspace.c $(WS_TDEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -Iports/cross -Iports/common -o $@ $< $(WS_TSRC) $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_workspace_float: tests/test_runtime_workspace.c $(WS_TDEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -Iports/cross -Iports/common -DSN_FLOAT -o $@ $< $(WS_TSRC) $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_workspace $(BUILD)/tests/test_runtime_workspace_float
TEST_DEPS += $(WS_BLOBS)

# A true hierarchical solve, measured (runtime/LEVELS.md §3; tests/hier_study.c): double
# precision, host only. `make hier-study` prints the tables; make test runs the Galerkin
# identity of the hierarchical elements (--check-only, cow and beast, a few seconds).
$(BUILD)/tests/hier_study: tests/hier_study.c tests/sn_test.h $(TOOLS_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itools -Itools/ref -Itests -o $@ $< $(TOOLS_LIB) -lm
.PHONY: hier-study hier-study-dynamics
hier-study: $(BUILD)/tests/hier_study
	$(BUILD)/tests/hier_study tools/examples/cow/cow.sinew
	$(BUILD)/tests/hier_study tools/examples/beast/beast.sinew
# the same over 48 steps per pose (about 10 minutes of CPU: dense double solves of level 1 each step)
hier-study-dynamics: $(BUILD)/tests/hier_study
	$(BUILD)/tests/hier_study tools/examples/cow/cow.sinew --dynamics 48 0
	$(BUILD)/tests/hier_study tools/examples/cow/cow.sinew --dynamics 48 1
	$(BUILD)/tests/hier_study tools/examples/beast/beast.sinew --dynamics 48 0
	$(BUILD)/tests/hier_study tools/examples/beast/beast.sinew --dynamics 48 1
$(BUILD)/tests/test_bake_hier: tests/hier_study.c tests/sn_test.h $(TOOLS_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -DHIER_TEST -Itools -Itools/ref -Itests -o $@ $< $(TOOLS_LIB) -lm
TEST_BINS += $(BUILD)/tests/test_bake_hier
# The study as a picture (LEVELS.md §3): the cow's head turn and the beast's neck turn, level 0 |
# cut k = 0 | k = 50 | level 1 coloured by distance from level 1; about 9 s of CPU, not in make test.
HIER_PIC_SRC = ports/desktop/raster.c ports/desktop/png.c
$(BUILD)/tests/hier_picture: tests/hier_picture.c tests/hier_study.c tests/sn_test.h $(HIER_PIC_SRC) ports/desktop/raster.h ports/desktop/png.h $(TOOLS_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itools -Itools/ref -Itests -Iports/desktop -o $@ $< $(HIER_PIC_SRC) $(TOOLS_LIB) -lm
.PHONY: hier-picture
hier-picture: $(BUILD)/tests/hier_picture
	$(BUILD)/tests/hier_picture ports/desktop/hier_levels.png
# what the details' cell kernels cost per mat-vec (callgrind; runtime/LEVELS.md §3): not a suite
$(BUILD)/tests/detail_cost: tests/detail_cost.c $(SN_TEST_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
TEST_DEPS += $(BUILD)/tests/detail_cost
