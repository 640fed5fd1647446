# ports/desktop build fragment: the CLI player in two flavours, its tests,
# and `make demo`.
#   $(BUILD)/sinew-play        fixed runtime ($(SN_LIB_FIXED))
#   $(BUILD)/sinew-play-float  same source, -DSN_FLOAT, float runtime
#   $(BUILD)/sinew-plot        line plots of the players' --stats-csv files
# ports/common (clip parser) is shared with the bare-metal port.
DESK_INC  = $(if $(SN_INC),$(SN_INC),-Iruntime/include) -Iruntime/src -Iports/common -Iports/desktop
DESK_HDRS = runtime/include/sinew.h runtime/src/sn_format.h ports/common/sn_clip.h \
            ports/desktop/raster.h ports/desktop/png.h ports/desktop/plot.h ports/desktop/play_gltf.h \
            tools/sb.h tools/sb_gltf.h tools/sb_gltf_int.h tools/sb_json.h
PLAY_SRCS = ports/desktop/play.c ports/desktop/raster.c ports/desktop/png.c ports/desktop/plot.c \
            ports/common/sn_clip.c ports/common/sn_clip_pose.c \
            ports/desktop/play_gltf.c tools/sb_json.c tools/sb_gltf_data.c tools/sb_gltf.c tools/sb_gltf_anim.c tools/sb_util.c
# the player reads glTF with the host tool's reader (issue 17: --gltf-anim, --out-gltf); a glTF
# animation keyed at every step needs more clip keys than the bare-metal default
PLAY_CFLAGS = -Itools -DSN_CLIP_MAX_KEYS=32768 -DSN_CLIP_MAX_CHANNELS=256
DEMO_DIR  = $(BUILD)/demo
COW_CLIPS = tools/examples/cow/head_turn.clip tools/examples/cow/trot.clip tools/examples/cow/breathe.clip \
            tools/examples/cow/smile.clip tools/examples/cow/belly.clip

# Tests that need no runtime.
$(BUILD)/tests/test_clip: tests/test_clip.c ports/common/sn_clip.c ports/common/sn_clip.h tests/sn_test.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) -Itests tests/test_clip.c ports/common/sn_clip.c -o $@ -lm

$(BUILD)/tests/test_png: tests/test_png.c ports/desktop/png.c ports/desktop/png.h tests/sn_test.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) -Itests tests/test_png.c ports/desktop/png.c -o $@ -lm

$(BUILD)/tests/test_desktop_raster: tests/test_desktop_raster.c ports/desktop/raster.c ports/desktop/raster.h tests/sn_test.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) -Itests tests/test_desktop_raster.c ports/desktop/raster.c -o $@ -lm

TEST_BINS += $(BUILD)/tests/test_clip $(BUILD)/tests/test_png $(BUILD)/tests/test_desktop_raster

# sinew-plot: plots of --stats-csv files (no runtime).
PLOT_SRCS = ports/desktop/plot_csv.c ports/desktop/plot.c ports/desktop/raster.c ports/desktop/png.c
all: $(BUILD)/sinew-plot
$(BUILD)/sinew-plot: $(PLOT_SRCS) ports/desktop/plot.h ports/desktop/raster.h ports/desktop/png.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) $(PLOT_SRCS) -o $@ -lm
TEST_DEPS += $(BUILD)/sinew-plot

# The player needs the runtime libraries (runtime/runtime.mk).
ifdef SN_LIB_FIXED
all: $(BUILD)/sinew-play $(BUILD)/sinew-play-float

$(BUILD)/sinew-play: $(PLAY_SRCS) $(DESK_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) $(PLAY_CFLAGS) $(PLAY_SRCS) $(SN_LIB_FIXED) -o $@ -lm

$(BUILD)/sinew-play-float: $(PLAY_SRCS) $(DESK_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -DSN_FLOAT $(DESK_INC) $(PLAY_CFLAGS) $(PLAY_SRCS) $(SN_LIB_FLOAT) -o $@ -lm

# Clip sampling through the runtime against a double reference.
$(BUILD)/tests/test_clip_pose: tests/test_clip_pose.c ports/common/sn_clip.c ports/common/sn_clip_pose.c \
                               ports/common/sn_clip.h tests/sn_test.h $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(DESK_INC) -Itests tests/test_clip_pose.c ports/common/sn_clip.c \
	    ports/common/sn_clip_pose.c $(SN_LIB_FIXED) -o $@ -lm

$(BUILD)/tests/test_clip_pose_float: tests/test_clip_pose.c ports/common/sn_clip.c ports/common/sn_clip_pose.c \
                                     ports/common/sn_clip.h tests/sn_test.h $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -DSN_FLOAT $(DESK_INC) -Itests tests/test_clip_pose.c ports/common/sn_clip.c \
	    ports/common/sn_clip_pose.c $(SN_LIB_FLOAT) -o $@ -lm

TEST_BINS += $(BUILD)/tests/test_clip_pose $(BUILD)/tests/test_clip_pose_float
TEST_DEPS += $(BUILD)/sinew-play $(BUILD)/sinew-play-float
endif

# make demo: bake the cow, play both clips in both flavours, write pictures.
demo: $(BUILD)/sinew-play $(BUILD)/sinew-play-float $(BUILD)/examples/cow.blob $(BUILD)/examples/cow_float.blob \
      $(BUILD)/examples/limb.blob $(BUILD)/examples/limb_crease.blob $(BUILD)/examples/limb_crease_none.blob $(BUILD)/examples/beast.blob $(BUILD)/examples/beast_crease.blob $(COW_CLIPS) $(SHEET_BLOBS) $(BUILD)/sinew-rig $(BUILD)/sinew-bake
	@BUILD=$(BUILD) sh ports/desktop/demo.sh

# ---- glTF with Blender (issue 17 item 5; tools/blender/) ----
# make gltf-roundtrip: the Blender-exported cow baked, its walk played with
# --out-gltf, and the result imported by Blender's own glTF importer
# (tools/blender/import_check.py); skipped, with the reason, without Blender.
# make gltf-assets: regenerate tools/examples/{cow,beast}_gltf/*.glb and the
# bone heads with Blender (tools/blender/make_gltf.py); only for maintainers.
BLENDER ?= blender
BLENDER_RUN = $(BLENDER) -b --factory-startup --python-exit-code 1 -P
.PHONY: gltf-roundtrip gltf-assets
gltf-roundtrip: $(BUILD)/sinew-play $(BAKE)
	@if ! command -v $(BLENDER) > /dev/null 2>&1; then \
	    echo "gltf-roundtrip: SKIPPED: '$(BLENDER)' not found (apt-get install blender, or BLENDER=/path/to/blender)"; \
	else \
	    mkdir -p $(BUILD)/gltf && \
	    $(BAKE) tools/examples/cow_gltf/cow_gltf.sinew -o $(BUILD)/gltf/cow_gltf.blob --quiet && \
	    $(BUILD)/sinew-play $(BUILD)/gltf/cow_gltf.blob --gltf-anim tools/examples/cow_gltf/cow.glb:walk --quiet \
	        --out-gltf $(BUILD)/gltf/cow_walk.glb && \
	    $(BLENDER_RUN) tools/blender/import_check.py -- $(BUILD)/gltf/cow_walk.glb > $(BUILD)/gltf/import.log 2>&1 && \
	    grep '^import_check:' $(BUILD)/gltf/import.log || { echo "gltf-roundtrip: FAILED (log: $(BUILD)/gltf/import.log)"; exit 1; }; \
	fi
gltf-assets:
	$(BLENDER_RUN) tools/blender/make_gltf.py -- --obj tools/examples/cow/cow.obj --desc tools/examples/cow/cow.sinew \
	    --walk cow --out tools/examples/cow_gltf/cow.glb --heads tools/examples/cow_gltf/cow_heads.txt
	$(BLENDER_RUN) tools/blender/make_gltf.py -- --obj tools/examples/beast/beast.obj --desc tools/examples/beast/beast.sinew \
	    --walk biped --normals 0 --out tools/examples/beast_gltf/beast.glb --heads tools/examples/beast_gltf/beast_heads.txt
