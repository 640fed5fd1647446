# libFuzzer harnesses (issue 16 item 5). Included from the top-level Makefile
# after tests/tests.mk. Built with clang -fsanitize=fuzzer,address,undefined
# when clang is on PATH (under CI=true tests/scripts/test_fuzz.sh fails
# without it; .ci/install-deps.sh installs clang and libclang-rt-14-dev).
#
#   $(FUZZ_DIR)/fuzz_blob_fixed   validator + instance + step, fixed runtime (tests/fuzz/lf_blob.c)
#   $(FUZZ_DIR)/fuzz_blob_float   the same, float runtime (-DSN_FLOAT)
#   $(FUZZ_DIR)/fuzz_clip         clip parser + sampler (ports/common; tests/fuzz/lf_clip.c)
#   $(FUZZ_DIR)/fuzz_desc         description reader (tools/sb_desc.c; tests/fuzz/lf_desc.c)
#   $(FUZZ_DIR)/fuzz_obj          OBJ reader + inside test (tools/sb_mesh.c; tests/fuzz/lf_obj.c)
#   $(FUZZ_DIR)/fuzz_gltf         glTF 2.0 reader and animations (tools/sb_gltf*.c, sb_json.c; tests/fuzz/lf_gltf.c)
#
# Seeds: tests/fuzz/corpus/<harness>/ (in the tree: clips, descriptions, OBJs)
# plus $(FUZZ_DIR)/seeds/<harness>/ generated at build time (blobs of the
# test writer tests/fuzz/sn_tblob.h, the baked examples' blobs, the example
# clips/descriptions/meshes), so the blob seeds always follow sn_format.h.
#
#   make test            runs each harness FUZZ_SECONDS (default 6) s from a fresh work dir
#   make fuzz            the long campaign: FUZZ_SECONDS (default 600) s per harness,
#                        new inputs kept in $(FUZZ_DIR)/work/<harness>/ across runs;
#                        FUZZ_HARNESSES="fuzz_obj fuzz_desc" picks some
#   make fuzz-seeds      copy the generated blob seeds into tests/fuzz/corpus/ (after a format change)
# A finding is saved as $(FUZZ_DIR)/artifacts/<harness>-crash-*; replay it with
# `$(FUZZ_DIR)/<harness> FILE` (fuzz_clip also needs SN_LF_BLOB=$(BUILD)/examples/cow.blob).
FUZZ_DIR   = $(BUILD)/fuzz
FUZZ_CC   ?= clang
FUZZ_HAVE := $(shell command -v $(FUZZ_CC) 2>/dev/null)
LF_CFLAGS  = -std=c99 -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer,address,undefined \
             -fno-sanitize-recover=all -Itests/fuzz
# the runtime as objects, once per flavour: fuzz_blob_fixed and fuzz_clip link
# the same fixed objects (one compilation instead of two; -j2 spreads them)
LF_OBJ     = $(FUZZ_DIR)/obj
LF_RT_INC  = $(SN_INC) -Iruntime/src
lf_rt      = $(patsubst runtime/src/%.c,$(LF_OBJ)/$(1)/%.o,$(SN_SRCS))
$(LF_OBJ)/fixed/%.o: runtime/src/%.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) $(LF_RT_INC) -c $< -o $@
$(LF_OBJ)/float/%.o: runtime/src/%.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) $(LF_RT_INC) -DSN_FLOAT -c $< -o $@
LF_NAMES   = fuzz_blob_fixed fuzz_blob_float fuzz_clip fuzz_desc fuzz_obj fuzz_gltf
LF_BINS    = $(addprefix $(FUZZ_DIR)/,$(LF_NAMES))
LF_SEEDS   = $(addprefix $(FUZZ_DIR)/seeds/,$(addsuffix /.stamp,$(LF_NAMES)))

$(FUZZ_DIR)/fuzz_blob_fixed: tests/fuzz/lf_blob.c tests/fuzz/lf_common.h tests/fuzz/sn_thostile.h $(SN_HDRS) $(call lf_rt,fixed)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) $(LF_RT_INC) -o $@ $< $(call lf_rt,fixed) -lm
$(FUZZ_DIR)/fuzz_blob_float: tests/fuzz/lf_blob.c tests/fuzz/lf_common.h tests/fuzz/sn_thostile.h $(SN_HDRS) $(call lf_rt,float)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) $(LF_RT_INC) -DSN_FLOAT -o $@ $< $(call lf_rt,float) -lm
$(FUZZ_DIR)/fuzz_clip: tests/fuzz/lf_clip.c tests/fuzz/lf_common.h ports/common/sn_clip.c ports/common/sn_clip_pose.c \
                       ports/common/sn_clip.h $(SN_HDRS) $(call lf_rt,fixed)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) $(LF_RT_INC) -Iports/common -o $@ $< ports/common/sn_clip.c ports/common/sn_clip_pose.c $(call lf_rt,fixed) -lm
# the description reader reads `gltf FILE` lines through the glTF bake (and its mesh checks)
LF_DESC_SRC = tools/sb_desc.c tools/sb_desc_args.c tools/sb_desc_body.c tools/sb_desc_sim.c tools/sb_desc_rig.c tools/sb_desc_seg.c tools/sb_util.c tools/sb_mesh.c tools/sb_gltf_bake.c tools/sb_gltf.c tools/sb_gltf_data.c tools/sb_gltf_anim.c tools/sb_json.c
$(FUZZ_DIR)/fuzz_desc: tests/fuzz/lf_desc.c tests/fuzz/lf_common.h $(LF_DESC_SRC) tools/sb.h $(GLTF_HDR)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) -Itools -o $@ $< $(LF_DESC_SRC) -lm
$(FUZZ_DIR)/fuzz_obj: tests/fuzz/lf_obj.c tests/fuzz/lf_common.h tools/sb_mesh.c tools/sb_util.c tools/sb.h
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) -Itools -o $@ $< tools/sb_mesh.c tools/sb_util.c -lm
LF_GLTF_SRC = tools/sb_gltf.c tools/sb_gltf_data.c tools/sb_gltf_anim.c tools/sb_json.c tools/sb_util.c
$(FUZZ_DIR)/fuzz_gltf: tests/fuzz/lf_gltf.c tests/fuzz/lf_common.h $(LF_GLTF_SRC) tools/sb.h $(GLTF_HDR)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(LF_CFLAGS) -Itools -o $@ $< $(LF_GLTF_SRC) -lm

# ---- generated seeds ----
$(FUZZ_DIR)/lf_seed_blob_fixed: tests/fuzz/lf_seed_blob.c tests/fuzz/sn_tblob.h $(SN_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
$(FUZZ_DIR)/lf_seed_blob_float: tests/fuzz/lf_seed_blob.c tests/fuzz/sn_tblob.h $(SN_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ $< $(SN_LIB_FLOAT) -lm
# a writer that falls behind the format only costs its seeds (reported), not the build
$(FUZZ_DIR)/seeds/fuzz_blob_fixed/.stamp: $(FUZZ_DIR)/lf_seed_blob_fixed $(EX)/cow.blob $(EX)/limb.blob $(EX)/beam1.blob $(LEVEL_EX)/limb_cut.blob
	@rm -rf $(@D) && mkdir -p $(@D)
	-$(FUZZ_DIR)/lf_seed_blob_fixed $(@D)
	cp $(EX)/cow.blob $(EX)/limb.blob $(EX)/beam1.blob $(LEVEL_EX)/limb_cut.blob $(@D)/
	@touch $@
$(FUZZ_DIR)/seeds/fuzz_blob_float/.stamp: $(FUZZ_DIR)/lf_seed_blob_float $(EX)/cow_float.blob $(EX)/limb_float.blob $(EX)/beam1_float.blob $(LEVEL_EX)/limb_cut_float.blob
	@rm -rf $(@D) && mkdir -p $(@D)
	-$(FUZZ_DIR)/lf_seed_blob_float $(@D)
	cp $(EX)/cow_float.blob $(EX)/limb_float.blob $(EX)/beam1_float.blob $(LEVEL_EX)/limb_cut_float.blob $(@D)/
	@touch $@
$(FUZZ_DIR)/seeds/fuzz_clip/.stamp: $(wildcard tools/examples/*/*.clip)
	@rm -rf $(@D) && mkdir -p $(@D)
	for f in tools/examples/*/*.clip; do cp $$f $(@D)/$$(basename $$(dirname $$f))_$$(basename $$f); done
	@touch $@
$(FUZZ_DIR)/seeds/fuzz_desc/.stamp: $(wildcard tools/examples/*/*.sinew)
	@rm -rf $(@D) && mkdir -p $(@D)
	for f in tools/examples/*/*.sinew; do cp $$f $(@D)/; done
	@touch $@
# the examples' meshes are 0.1-3 MB: only the small ones (limb, diag) seed the OBJ reader
$(FUZZ_DIR)/seeds/fuzz_obj/.stamp: tools/examples/limb/limb.obj tools/examples/diag/diag.obj
	@rm -rf $(@D) && mkdir -p $(@D)
	cp tools/examples/limb/limb.obj tools/examples/diag/diag.obj $(@D)/
	@touch $@
# the glTF seeds are all in tests/fuzz/corpus/fuzz_gltf/: strip.glb and strip_datauri.gltf (written by
# test_bake_gltf), strip_anim.gltf (the data-URI strip with two animations: LINEAR, STEP, CUBICSPLINE,
# translation and scale channels; issue 17 item 3) and regress_anim_time_uaf.gltf (a use after free
# fuzz_gltf found in sb_gltf_anim.c, fixed)
$(FUZZ_DIR)/seeds/fuzz_gltf/.stamp:
	@rm -rf $(@D) && mkdir -p $(@D)
	@touch $@

.PHONY: fuzz fuzz-bins fuzz-seeds
fuzz-bins: $(LF_BINS) $(LF_SEEDS) $(EX)/cow.blob
fuzz: fuzz-bins
	BUILD=$(BUILD) FUZZ_SECONDS=$${FUZZ_SECONDS:-600} FUZZ_KEEP=1 sh tests/scripts/test_fuzz.sh $(FUZZ_HARNESSES)
fuzz-seeds: $(LF_SEEDS)
	for h in fuzz_blob_fixed fuzz_blob_float; do mkdir -p tests/fuzz/corpus/$$h; \
	  cp $(FUZZ_DIR)/seeds/$$h/tblob_*.blob tests/fuzz/corpus/$$h/; done

# make test: the short run (tests/scripts/test_fuzz.sh) needs the harnesses
# and their seeds; without clang the script reports SKIPPED (a failure under CI).
# Prerequisites of test-build, not of test: `make test` itself runs without
# -j, so its own prerequisites would be built one at a time.
ifneq ($(FUZZ_HAVE),)
test-build: fuzz-bins
endif

# blob_patch: sets a header real and fixes the CRC (tests/scripts/test_player_timestep.sh)
$(BUILD)/tests/blob_patch: tests/fuzz/blob_patch.c runtime/src/sn_format.h tools/sb_util.c tools/sb.h
	@mkdir -p $(@D)
	$(CC) -std=c99 -Wall -Wextra -Werror $(CFLAGS) -Iruntime/src -Itools -o $@ $< tools/sb_util.c -lm
test-build: $(BUILD)/tests/blob_patch

# ---- expected state hashes (tests/expected_hashes.txt, checked by
# tests/scripts/test_determinism.sh): rewrite them on purpose after a change
# meant to alter the simulation. (Kept in this fragment so the Makefile
# gains a single include line.)
.PHONY: update-hashes
update-hashes: $(BUILD)/sinew-play $(BUILD)/sinew-play-float $(EX)/cow.blob $(EX)/cow_float.blob \
               $(BUILD)/cross/det_x86_64-gcc-O2 $(BUILD)/cross/det_float-gcc-O2 $(EX)/limb_crease.blob $(EX)/limb_crease_float.blob \
               $(LEVEL_EX)/cow_lod.blob $(LEVEL_EX)/cow_lod_float.blob $(LEVEL_EX)/cow_adapt.blob $(LEVEL_EX)/cow_adapt_float.blob \
               $(LEVEL_EX)/cow_cut.blob $(LEVEL_EX)/cow_cut_float.blob $(BUILD)/tests/test_runtime_dstep $(BUILD)/tests/test_runtime_dstep_float \
               $(LEVEL_EX)/cow_details.blob $(LEVEL_EX)/cow_details_float.blob
	BUILD=$(BUILD) sh tests/scripts/update_hashes.sh
