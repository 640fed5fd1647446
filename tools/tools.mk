# tools build fragment: the host tool sinew-bake (library + main) and the baked examples.
BAKE = $(BUILD)/sinew-bake
TOOLS_LIB_SRC = tools/sb_util.c tools/sb_mesh.c tools/sb_desc.c tools/sb_desc_args.c tools/sb_desc_body.c tools/sb_desc_sim.c tools/sb_desc_rig.c tools/sb_desc_seg.c tools/sb_lattice.c tools/sb_lattice_geom.c tools/sb_lattice_fill.c tools/sb_frames.c tools/sb_integrate.c tools/sb_level.c tools/sb_cut.c tools/sb_rig.c tools/sb_force.c tools/sb_segment.c tools/sb_crease.c tools/ref/snref.c tools/sb_ichol.c tools/sb_frefs.c tools/sb_blob.c tools/sb_blob_table.c tools/sb_blob_details.c tools/sb_blob_records.c tools/sb_blob_cells.c tools/sb_blob_rigs.c tools/sb_blob_file.c tools/sb_bake.c tools/sb_json.c tools/sb_gltf_data.c tools/sb_gltf.c tools/sb_lbfgsb.c tools/sb_rigfile.c tools/sb_gltf_bake.c tools/sb_gltf_anim.c tools/sb_retarget.c tools/sb_retarget_surf.c tools/sb_retarget_xfer.c
TOOLS_LIB_OBJ = $(patsubst tools/%.c,$(BUILD)/tools/%.o,$(TOOLS_LIB_SRC))
TOOLS_LIB = $(BUILD)/tools/libsinewbake.a
TOOLS_HDR = tools/sb.h tools/sb_desc_int.h tools/sb_blob_int.h tools/sb_level.h tools/sb_cut.h tools/sb_lbfgsb.h tools/sb_retarget.h tools/sb_retarget_int.h runtime/src/sn_format.h tools/ref/snref.h
# the glTF reader (issue 17): its own headers
GLTF_HDR = tools/sb_json.h tools/sb_gltf.h tools/sb_gltf_int.h
$(BUILD)/tools/sb_json.o $(BUILD)/tools/sb_gltf_data.o $(BUILD)/tools/sb_gltf.o $(BUILD)/tools/sb_gltf_bake.o $(BUILD)/tools/sb_gltf_anim.o $(BUILD)/tools/sb_desc.o $(BUILD)/tools/sb_frames.o $(BUILD)/tests/test_bake_gltf: $(GLTF_HDR)

$(BUILD)/tools/%.o: tools/%.c $(TOOLS_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -c $< -o $@

$(TOOLS_LIB): $(TOOLS_LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $(TOOLS_LIB_OBJ)

# sinew-bake --static (tools/sb_static.c): the double-precision reference
# model (tools/ref/snref.c), the clip parser (ports/common/sn_clip.c: no
# runtime calls) and the desktop rasterizer and PNG writer.
STATIC_SRC = tools/sb_static.c ports/common/sn_clip.c ports/desktop/raster.c ports/desktop/png.c
STATIC_OBJ = $(BUILD)/tools/static/sb_static.o $(BUILD)/tools/static/sn_clip.o \
             $(BUILD)/tools/static/raster.o $(BUILD)/tools/static/png.o
STATIC_INC = -Itools -Itools/ref -Iruntime/include -Iruntime/src -Iports/common -Iports/desktop
STATIC_HDR = tools/sb_static.h tools/ref/snref.h ports/common/sn_clip.h ports/desktop/raster.h ports/desktop/png.h $(TOOLS_HDR)
$(BUILD)/tools/static/%.o: tools/%.c $(STATIC_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -c $< -o $@
$(BUILD)/tools/static/%.o: tools/ref/%.c $(STATIC_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -c $< -o $@
$(BUILD)/tools/static/%.o: ports/common/%.c $(STATIC_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -c $< -o $@
$(BUILD)/tools/static/%.o: ports/desktop/%.c $(STATIC_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -c $< -o $@
$(BUILD)/tools/sinew_bake.o $(BUILD)/tools/sb_crease.o: tools/sb_static.h

$(BAKE): $(BUILD)/tools/sinew_bake.o $(TOOLS_LIB) $(STATIC_OBJ)
	$(CC) $(HOST_CFLAGS) -o $@ $(BUILD)/tools/sinew_bake.o $(STATIC_OBJ) $(TOOLS_LIB) -lm

# sinew-rig (issue 11): rig fitting on the double-precision reference model,
# tools/sb_fit.c (costs, adjoint, pose fit) over L-BFGS-B (tools/sb_lbfgsb.c).
RIGTOOL = $(BUILD)/sinew-rig
RIG_SRC = tools/sb_fit.c tools/sinew_rig.c tools/sinew_rig_args.c tools/sinew_rig_report.c tools/sinew_rig_export.c tools/sinew_rig_pose.c tools/sinew_rig_surface.c tools/sinew_rig_points.c tools/sb_retarget_cli.c   # + TOOLS_LIB_SRC and STATIC_SRC (the CMake build reads this list)
FIT_OBJ = $(BUILD)/tools/static/sb_fit.o
RIG_CLI_OBJ = $(patsubst tools/%.c,$(BUILD)/tools/static/%.o,$(filter tools/sinew_rig%.c,$(RIG_SRC))) $(BUILD)/tools/static/sb_retarget_cli.o
$(FIT_OBJ) $(RIG_CLI_OBJ): tools/sb_fit.h tools/sinew_rig_int.h
$(RIGTOOL): $(RIG_CLI_OBJ) $(FIT_OBJ) $(TOOLS_LIB) $(STATIC_OBJ)
	$(CC) $(HOST_CFLAGS) -o $@ $(RIG_CLI_OBJ) $(FIT_OBJ) $(STATIC_OBJ) $(TOOLS_LIB) -lm
all: $(RIGTOOL)
$(BUILD)/tests/test_rigfit: tests/test_rigfit.c $(FIT_OBJ) $(STATIC_OBJ) $(TOOLS_LIB) tools/sb_fit.h tests/sn_test.h
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -Itests -o $@ $< $(FIT_OBJ) $(STATIC_OBJ) $(TOOLS_LIB) -lm
TEST_BINS += $(BUILD)/tests/test_rigfit
TEST_DEPS += $(RIGTOOL)
# rig files on level 1 of 'levels 2' (issue 13): the checker tests/scripts/test_rigfile_levels.sh runs
$(BUILD)/tests/rig_level_check: tests/rig_level_check.c $(FIT_OBJ) $(STATIC_OBJ) $(TOOLS_LIB) tools/sb_fit.h tests/sn_test.h
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(STATIC_INC) -Itests -o $@ $< $(FIT_OBJ) $(STATIC_OBJ) $(TOOLS_LIB) -lm
TEST_DEPS += $(BUILD)/tests/rig_level_check

# ---- baked examples ----
EX = $(BUILD)/examples
COW_DEPS = tools/examples/cow/cow.sinew tools/examples/cow/cow.obj $(BAKE)
LIMB_DEPS = tools/examples/limb/limb.sinew tools/examples/limb/limb.obj $(BAKE)

$(EX)/cow.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --quiet
$(EX)/cow_blob.c: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew --c-array $@ --name sinew_cow_blob --quiet
$(EX)/cow_float.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --flavour float --quiet
$(EX)/cow_double.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --flavour double --quiet

$(EX)/limb.blob: $(LIMB_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb.sinew -o $@ --quiet
$(EX)/limb_blob.c: $(LIMB_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb.sinew --c-array $@ --name sinew_limb_blob --quiet
$(EX)/limb_float.blob: $(LIMB_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb.sinew -o $@ --flavour float --quiet
$(EX)/limb_double.blob: $(LIMB_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb.sinew -o $@ --flavour double --quiet

# the limb with crease self-collision (seed 003 §3.4); _small: list 2,
# active 1 (the overflow test)
LIMBC_DEPS = tools/examples/limb/limb_crease.sinew tools/examples/limb/limb.obj $(BAKE)
$(EX)/limb_crease.blob: $(LIMBC_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb_crease.sinew -o $@ --quiet
$(EX)/limb_crease_float.blob: $(LIMBC_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/limb/limb_crease.sinew -o $@ --flavour float --quiet
$(EX)/limb_crease_small/limb.sinew: tools/examples/limb/limb_crease.sinew tools/examples/limb/limb.obj
	@mkdir -p $(@D)
	sed 's/^crease_settings .*/crease_settings list 2 active 1 ring 1 depth 0.5 push 0.125/' $< > $@
	cp tools/examples/limb/limb.obj $(@D)/limb.obj
$(EX)/limb_crease_small.blob: $(EX)/limb_crease_small/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(EX)/limb_crease_small_float.blob: $(EX)/limb_crease_small/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
# _none: the same lattice without crease data (the comparison without collision)
$(EX)/limb_crease_none/limb.sinew: tools/examples/limb/limb_crease.sinew tools/examples/limb/limb.obj
	@mkdir -p $(@D)
	sed '/^crease/d' $< > $@
	cp tools/examples/limb/limb.obj $(@D)/limb.obj
$(EX)/limb_crease_none.blob: $(EX)/limb_crease_none/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(EX)/limb_crease_none_float.blob: $(EX)/limb_crease_none/limb.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
CREASE_BLOBS = $(EX)/limb_crease.blob $(EX)/limb_crease_float.blob $(EX)/limb_crease_small.blob $(EX)/limb_crease_small_float.blob \
               $(EX)/limb_crease_none.blob $(EX)/limb_crease_none_float.blob

# cantilever beams with 1, 2, 4 cells through the height (generated by
# tools/examples/beam/make_beam.sh into $(EX)/beamN/); beam.blob = 2 cells.
BEAM_GEN = tools/examples/beam/make_beam.sh tools/examples/make_box.sh
$(EX)/beam%/beam.sinew: $(BEAM_GEN)
	sh tools/examples/beam/make_beam.sh $* $(EX)/beam$*
$(EX)/beam%.blob: $(EX)/beam%/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(EX)/beam%_float.blob: $(EX)/beam%/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
$(EX)/beam%_double.blob: $(EX)/beam%/beam.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour double --quiet
$(EX)/beam.blob: $(EX)/beam2.blob
	cp $< $@
.PRECIOUS: $(EX)/beam%/beam.sinew

EXAMPLE_BLOBS = $(EX)/cow.blob $(EX)/cow_float.blob $(EX)/cow_double.blob $(EX)/cow_blob.c \
                $(EX)/limb.blob $(EX)/limb_float.blob $(EX)/limb_double.blob $(EX)/limb_blob.c \
                $(EX)/beam.blob $(EX)/beam1.blob $(EX)/beam2.blob $(EX)/beam4.blob \
                $(EX)/beam1_float.blob $(EX)/beam2_float.blob $(EX)/beam4_float.blob \
                $(EX)/beam1_double.blob $(EX)/beam2_double.blob $(EX)/beam4_double.blob $(CREASE_BLOBS)
TEST_DEPS += $(EXAMPLE_BLOBS)

all: $(BAKE) $(EXAMPLE_BLOBS)

# ---- tests of the tool (tests/test_bake*.c link the tool library) ----
BAKE_TESTS = $(patsubst tests/%.c,$(BUILD)/tests/%,$(wildcard tests/test_bake*.c))
$(BUILD)/tests/test_bake%: tests/test_bake%.c $(TOOLS_LIB) $(TOOLS_HDR) tests/sn_test.h
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itools -Itests -Iruntime/src -o $@ $< $(TOOLS_LIB) -lm
TEST_BINS += $(BAKE_TESTS)

# ---- the beast (tools/examples/beast): humanoid, 32k-vertex surface ----
BEAST_DEPS = tools/examples/beast/beast.sinew tools/examples/beast/beast.obj $(BAKE)
$(EX)/beast.blob: $(BEAST_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/beast/beast.sinew -o $@ --quiet
$(EX)/beast_float.blob: $(BEAST_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/beast/beast.sinew -o $@ --flavour float --quiet
$(EX)/beast_double.blob: $(BEAST_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/beast/beast.sinew -o $@ --flavour double --quiet
BEAST_BLOBS = $(EX)/beast.blob $(EX)/beast_float.blob $(EX)/beast_double.blob
# the beast with crease self-collision (elbows, knees, arms against the flanks)
$(EX)/beast_crease/beast.sinew: tools/examples/beast/beast.sinew tools/examples/beast/crease.lines tools/examples/beast/beast.obj
	@mkdir -p $(@D)
	cat tools/examples/beast/beast.sinew tools/examples/beast/crease.lines > $@
	cp tools/examples/beast/beast.obj $(@D)/beast.obj
$(EX)/beast_crease.blob: $(EX)/beast_crease/beast.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(EX)/beast_crease_float.blob: $(EX)/beast_crease/beast.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
TEST_DEPS += $(BEAST_BLOBS)
# the humanoid's crease test (tests/test_runtime_crease.c, SN_CREASE_BEAST=1)
# in both flavours: a campaign (tests/CAMPAIGNS.md; 32 CPU-s a bake, 4 a run)
.PHONY: crease-beast
crease-beast: $(EX)/beast_crease.blob $(EX)/beast_crease_float.blob $(BUILD)/tests/test_runtime_crease $(BUILD)/tests/test_runtime_crease_float
	SN_CREASE_BEAST=1 BUILD=$(BUILD) $(BUILD)/tests/test_runtime_crease
	SN_CREASE_BEAST=1 BUILD=$(BUILD) $(BUILD)/tests/test_runtime_crease_float
all: $(BEAST_BLOBS)

# ---- glTF examples (tools/examples/*_gltf, issue 17): Blender exports, 'gltf' descriptions;
# each bake also writes BLOB.gltfmap (the glTF vertex order) ----
$(EX)/cow_gltf.blob: tools/examples/cow_gltf/cow_gltf.sinew tools/examples/cow_gltf/cow.glb $(BAKE)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow_gltf/cow_gltf.sinew -o $@ --quiet
$(EX)/beast_gltf.blob: tools/examples/beast_gltf/beast_gltf.sinew tools/examples/beast_gltf/beast.glb $(BAKE)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/beast_gltf/beast_gltf.sinew -o $@ --quiet
all: $(EX)/cow_gltf.blob $(EX)/beast_gltf.blob

# ---- diag (tools/examples/diag): synthetic character, bones at 30/45/60 degrees ----
DIAG_DEPS = tools/examples/diag/diag.sinew tools/examples/diag/diag.obj $(BAKE)
$(EX)/diag.blob: $(DIAG_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/diag/diag.sinew -o $@ --quiet
$(EX)/diag_float.blob: $(DIAG_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/diag/diag.sinew -o $@ --flavour float --quiet
all: $(EX)/diag.blob $(EX)/diag_float.blob

# ---- the sheet experiments of seed 004 ch. 3-4 (tools/examples/sheet): a free
# 9x9 segment sheet; variants by make_sheet.sh (shares fine/equal/coarse,
# gravity off; floor_*: gravity on, tilted) into $(EX)/sheet_VARIANT/ ----
SHEET_VARIANTS = fine equal coarse floor_fine floor_equal floor_coarse
SHEET_GEN = tools/examples/sheet/make_sheet.sh tools/examples/sheet/sheet.sinew tools/examples/sheet/sheet.obj
$(EX)/sheet_%/sheet.sinew: $(SHEET_GEN)
	sh tools/examples/sheet/make_sheet.sh $* $(EX)/sheet_$*
$(EX)/sheet_%.blob: $(EX)/sheet_%/sheet.sinew $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(EX)/sheet_%_float.blob: $(EX)/sheet_%/sheet.sinew $(BAKE)
	$(BAKE) $< -o $@ --flavour float --quiet
$(EX)/sheet.blob: tools/examples/sheet/sheet.sinew tools/examples/sheet/sheet.obj $(BAKE)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/sheet/sheet.sinew -o $@ --quiet
.PRECIOUS: $(EX)/sheet_%/sheet.sinew
SHEET_BLOBS = $(EX)/sheet.blob $(patsubst %,$(EX)/sheet_%.blob,$(SHEET_VARIANTS)) \
              $(patsubst %,$(EX)/sheet_%_float.blob,$(SHEET_VARIANTS))
all: $(SHEET_BLOBS)
TEST_DEPS += $(SHEET_BLOBS)

# sinew-rig retarget (seed 003 §4.4): tools/sb_retarget_cli.c, the sub-command's own file, linked into $(RIGTOOL) above
# Spot (tools/examples/spot): the retargeting target, with the cow's smile as a rig file
SPOT_DEPS = tools/examples/spot/spot.sinew tools/examples/spot/spot.obj tools/examples/spot/spot_smile.rig $(BAKE)
$(EX)/spot.blob: $(SPOT_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/spot/spot.sinew -o $@ --quiet
all: $(EX)/spot.blob
