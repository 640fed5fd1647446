# tools build fragment: the host tool sinew-bake (library + main) and the baked examples.
BAKE = $(BUILD)/sinew-bake
TOOLS_LIB_SRC = tools/sb_util.c tools/sb_mesh.c tools/sb_desc.c tools/sb_lattice.c tools/sb_integrate.c tools/sb_blob.c tools/sb_bake.c
TOOLS_LIB_OBJ = $(patsubst tools/%.c,$(BUILD)/tools/%.o,$(TOOLS_LIB_SRC))
TOOLS_LIB = $(BUILD)/tools/libsinewbake.a
TOOLS_HDR = tools/sb.h runtime/src/sn_format.h

$(BUILD)/tools/%.o: tools/%.c $(TOOLS_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -c $< -o $@

$(TOOLS_LIB): $(TOOLS_LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $(TOOLS_LIB_OBJ)

$(BAKE): $(BUILD)/tools/sinew_bake.o $(TOOLS_LIB)
	$(CC) $(HOST_CFLAGS) -o $@ $(BUILD)/tools/sinew_bake.o $(TOOLS_LIB) -lm

# ---- baked examples ----
EX = $(BUILD)/examples
COW_DEPS = tools/examples/cow/cow.sinew tools/examples/cow/cow.obj $(BAKE)
LIMB_DEPS = tools/examples/limb/limb.sinew tools/examples/limb/limb.obj $(BAKE)

$(EX)/cow.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --c-array $(EX)/cow_blob.c --name sinew_cow_blob --quiet
$(EX)/cow_blob.c: $(EX)/cow.blob
$(EX)/cow_float.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --flavour float --quiet
$(EX)/cow_double.blob: $(COW_DEPS)
	@mkdir -p $(EX)
	$(BAKE) tools/examples/cow/cow.sinew -o $@ --flavour double --quiet

EXAMPLE_BLOBS = $(EX)/cow.blob $(EX)/cow_float.blob $(EX)/cow_double.blob $(EX)/cow_blob.c
TEST_DEPS += $(EXAMPLE_BLOBS)

all: $(BAKE) $(EXAMPLE_BLOBS)
