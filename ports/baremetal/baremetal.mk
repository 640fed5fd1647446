# ports/baremetal + ports/cross build fragment.
#   make ports            Cortex-M4 images (QEMU mps2-an386) + cross determinism drivers
#   make bench-baremetal  instructions per step on the Cortex-M4, flash/RAM (needs QEMU)
#   make profile-m4       Cortex-M4 instructions per step per function (QEMU plugin)
#   make determinism-m4  the full level-of-detail, adaptation and cut-level runs on the M4 (QEMU, ~1 min)
#   make bench-baremetal-level  their instructions per step on each level (qemu -icount, ~70 s)
#   make deps             install the cross toolchains and QEMU (Debian, root)
# Inputs from other fragments: SN_SRCS / SN_INC (runtime.mk), the host tool's
# C-array blobs $(BUILD)/examples/<asset>_blob.c (tools.mk).

.PHONY: deps ports-baremetal ports-cross bench-baremetal

deps:
	bash .ci/install-deps.sh

# ---- common inputs ----
PORT_SN_SRCS  = $(SN_SRCS)
PORT_SN_INC   = $(if $(SN_INC),$(SN_INC),-Iruntime/include)
# the runtime's own warning set (-Wconversion catches int widths that differ per target)
PORT_WARN     = -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Wvla -Werror
PORT_INC      = $(PORT_SN_INC) -Iports/common -Iports/cross
PORT_COMMON   = ports/cross/sn_det.c ports/common/sn_clip.c ports/common/sn_clip_pose.c
PORT_HDRS     = ports/cross/sn_det.h ports/common/sn_clip.h runtime/include/sinew.h \
                $(wildcard runtime/src/*.h)
COW_BLOB_C   ?= $(BUILD)/examples/cow_blob.c
LIMB_BLOB_C  ?= $(BUILD)/examples/limb_blob.c
COW_CLIP     ?= tools/examples/cow/trot.clip
LIMB_CLIP    ?= $(wildcard tools/examples/limb/*.clip)
COW_FLOAT_BLOB ?= $(BUILD)/examples/cow_float.blob
# the fixed drivers link the blob C array (as the image does); the float ones
# read $(COW_FLOAT_BLOB) at run time

# ---- Cortex-M4 images ----
BM_CC     ?= arm-none-eabi-gcc
BM_DIR     = $(BUILD)/baremetal
BM_ARCH    = -mcpu=cortex-m4 -mthumb -mfloat-abi=soft
BM_CFLAGS  = $(BM_ARCH) $(PORT_WARN) -O2 -g -ffunction-sections -fdata-sections \
             $(PORT_INC) -Iports/baremetal
BM_LDFLAGS = $(BM_ARCH) -nostartfiles --specs=nano.specs -T ports/baremetal/an386.ld \
             -Wl,--gc-sections
BM_STEPS  ?= 1000
BM_BENCH_STEPS ?= 100
# run: see BM_QEMU_RUN in ports/cross/port_lib.sh
BM_SRCS    = ports/baremetal/startup.c $(PORT_COMMON) $(PORT_SN_SRCS)
BM_OBJS    = $(patsubst %.c,$(BM_DIR)/obj/%.o,$(BM_SRCS))

$(BM_DIR)/obj/%.o: %.c $(PORT_HDRS) ports/baremetal/semihost.h
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@

# Generated C: blob arrays compiled as they come, clip text via bin2c.sh.
$(BM_DIR)/obj/cow_blob.o: $(COW_BLOB_C)
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@
$(BM_DIR)/obj/limb_blob.o: $(LIMB_BLOB_C)
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@
$(BM_DIR)/cow_clip.c: $(COW_CLIP) ports/baremetal/bin2c.sh
	@mkdir -p $(dir $@)
	sh ports/baremetal/bin2c.sh sn_bm_clip $(COW_CLIP) > $@
$(BM_DIR)/limb_clip.c: $(LIMB_CLIP) ports/baremetal/bin2c.sh
	@mkdir -p $(dir $@)
	sh ports/baremetal/bin2c.sh sn_bm_clip $(firstword $(LIMB_CLIP)) > $@
$(BM_DIR)/obj/%_clip.o: $(BM_DIR)/%_clip.c
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@

# cow_fem: the cow without its segment meshes (the model issue 15's goals were
# set on), baked in the build tree as runtime/bench/bench.sh bakes it: cow.sinew
# without its chain, sheet and attach lines, mesh path made absolute; the trot
COW_FEM_BLOB_C = $(BM_DIR)/gen/cow_fem_blob.c
$(BM_DIR)/gen/cow_fem.sinew: tools/examples/cow/cow.sinew
	@mkdir -p $(dir $@)
	grep -v -E '^(chain|sheet|attach) ' $< | sed "s#^mesh #mesh $(CURDIR)/tools/examples/cow/#" > $@
$(COW_FEM_BLOB_C): $(BM_DIR)/gen/cow_fem.sinew tools/examples/cow/cow.obj $(BAKE)
	$(BAKE) $< --c-array $@ --name sinew_cow_fem_blob --quiet
$(BM_DIR)/gen/cow_fem.blob: $(BM_DIR)/gen/cow_fem.sinew tools/examples/cow/cow.obj $(BAKE)
	$(BAKE) $< -o $@ --quiet
$(BM_DIR)/obj/cow_fem_blob.o: $(COW_FEM_BLOB_C)
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@
$(BM_DIR)/gen/cow_fem_inst.h: $(COW_FEM_BLOB_C) ports/baremetal/inst_bytes.sh
	sh ports/baremetal/inst_bytes.sh $< > $@
$(BM_DIR)/cow_fem_clip.c: $(COW_CLIP) ports/baremetal/bin2c.sh
	@mkdir -p $(dir $@)
	sh ports/baremetal/bin2c.sh sn_bm_clip $(COW_CLIP) > $@
.PHONY: print-blob-cow_fem
print-blob-cow_fem:
	@echo $(BM_DIR)/gen/cow_fem.blob

# the instance size of each blob, for main.c's static instance buffer
$(BM_DIR)/gen/%_inst.h: $(BUILD)/examples/%_blob.c ports/baremetal/inst_bytes.sh
	@mkdir -p $(dir $@)
	sh ports/baremetal/inst_bytes.sh $< > $@
$(BM_DIR)/gen/bad_inst.h:
	@mkdir -p $(dir $@)
	echo '#define SN_BM_INSTANCE_BYTES 8u' > $@

# main.c per image: asset, steps, clip or built-in poses, bench or not.
# $(1) image name, $(2) asset, $(3) steps, $(4) bench 0/1, $(5) clip file or empty
define bm_image
$(BM_DIR)/obj/main_$(1).o: ports/baremetal/main.c $(PORT_HDRS) ports/baremetal/semihost.h \
        $(BM_DIR)/gen/$(2)_inst.h
	@mkdir -p $$(dir $$@)
	$(BM_CC) $(BM_CFLAGS) -include $(BM_DIR)/gen/$(2)_inst.h -DSN_BM_BLOB=sinew_$(2)_blob -DSN_BM_BLOB_SIZE=sinew_$(2)_blob_size \
	    -DSN_BM_STEPS=$(3) -DSN_BM_BENCH=$(4) -DSN_BM_CLIP=$(if $(5),1,0) -c $$< -o $$@
$(BM_DIR)/$(1).elf: $(BM_DIR)/obj/main_$(1).o $(BM_OBJS) $(BM_DIR)/obj/$(2)_blob.o \
        $(if $(5),$(BM_DIR)/obj/$(2)_clip.o) ports/baremetal/an386.ld
	$(BM_CC) $(BM_LDFLAGS) -Wl,-Map,$$@.map -o $$@ $$(filter %.o,$$^)
endef
$(eval $(call bm_image,sinew_cow,cow,$(BM_STEPS),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,bench_cow,cow,$(BM_BENCH_STEPS),1,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,sinew_limb,limb,$(BM_STEPS),0,$(LIMB_CLIP)))
$(eval $(call bm_image,bench_limb,limb,$(BM_BENCH_STEPS),1,$(LIMB_CLIP)))
# make profile-m4: the same image at two step counts; the per-address
# difference over PROF_M4_STEPS steps is the per-step profile
PROF_M4_STEPS ?= 2 10
$(eval $(call bm_image,prof_cow_a,cow,$(word 1,$(PROF_M4_STEPS)),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,prof_cow_b,cow,$(word 2,$(PROF_M4_STEPS)),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,sinew_cow_fem,cow_fem,$(BM_STEPS),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,bench_cow_fem,cow_fem,$(BM_BENCH_STEPS),1,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,prof_cow_fem_a,cow_fem,$(word 1,$(PROF_M4_STEPS)),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,prof_cow_fem_b,cow_fem,$(word 2,$(PROF_M4_STEPS)),0,$(wildcard $(COW_CLIP))))
$(eval $(call bm_image,prof_limb_a,limb,$(word 1,$(PROF_M4_STEPS)),0,$(LIMB_CLIP)))
$(eval $(call bm_image,prof_limb_b,limb,$(word 2,$(PROF_M4_STEPS)),0,$(LIMB_CLIP)))
# the QEMU TCG plugin that counts instructions per address (host code)
$(BM_DIR)/insn_plugin.so: ports/baremetal/insn_plugin.c
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O2 -Wall -Wextra -Werror -shared -fPIC -o $@ $<
# tests/test_runtime_kernels.c on the M4 itself (the DSP kernels against
# the portable reference and the double references; test_baremetal.sh runs
# it): newlib's semihosting printf (rdimon.specs), the images' startup
$(BM_DIR)/obj/test_runtime_kernels.o: tests/test_runtime_kernels.c tests/sn_test.h $(PORT_HDRS)
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_ARCH) -std=c99 -O2 -Wall -Wextra -Werror -ffunction-sections -fdata-sections \
	    $(PORT_SN_INC) -Iruntime/src -Itests -Dmain=sn_test_main -c $< -o $@
$(BM_DIR)/test_kernels.elf: $(BM_DIR)/obj/test_runtime_kernels.o $(BM_DIR)/obj/ports/baremetal/test_main.o \
        $(BM_OBJS) ports/baremetal/an386.ld
	$(BM_CC) $(BM_ARCH) -nostartfiles --specs=nano.specs --specs=rdimon.specs -u _printf_float \
	    -T ports/baremetal/an386.ld -Wl,--gc-sections -Wl,--defsym,end=__bss_end -o $@ $(filter %.o,$^) -lm
$(BM_DIR)/obj/bad_blob.o: ports/baremetal/bad_blob.c
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@
$(eval $(call bm_image,bad_blob,bad,10,0,))

# ---- the level-of-detail and adaptation scenarios on the M4 (issue 13,
# main_level.c): det_main's --lod runs on tests/level.mk's two-level cow
# (cow_lod, own scratch) and its 'adapt' bake (cow_adapt, shared instance).
# The blobs are baked again as C arrays from tests/level.mk's descriptions
# (as tools.mk does cow_blob.c; the baker is deterministic, and the full run's
# hash is checked against tests/expected_hashes.txt, made from the .blob
# files). Full: 1000 steps, test_determinism.sh's LOD_SW (make determinism,
# make determinism-m4). Slice (make test): fewer steps, earlier switches, so
# level 1 and adaptation act within a few seconds of QEMU.
comma := ,
BM_LEVEL_LOD   = 250:1,500:0,750:1
BM_SLICE_STEPS = 60
BM_SLICE_LOD   = 20:1,40:0,50:1
# the cut level (cow_cut, LEVELS.md §2 "The cut level"): the full run is
# test_determinism.sh's cut scenario (tests/expected_hashes.txt cut_fixed);
# its slice has the level slice's steps and switches
BM_CUT_STEPS   = 200
BM_LEVEL_CUT   = 100:1,150:0
# details on the cut level (cow_details, LEVELS.md §3 "Details on the cut
# level"): details 0..BM_DETAILS_N-1 active from the first step at
# BM_DETAILS_ITERS CG iterations (det_main --details/--iterations), no level
# switch; the full run is test_determinism.sh's details scenario
# (tests/expected_hashes.txt details_trot_fixed), the slice fewer steps
BM_DETAILS_STEPS = 100
BM_DETAILS_SLICE_STEPS = 30
BM_DETAILS_N     = 50
BM_DETAILS_ITERS = 32
$(BM_DIR)/gen/cow_%_blob.c: $(BUILD)/level/cow/%.sinew $(BAKE)
	@mkdir -p $(dir $@)
	$(BAKE) $< --c-array $@ --name sinew_cow_$*_blob --quiet
.SECONDARY: $(BM_DIR)/gen/cow_lod_blob.c $(BM_DIR)/gen/cow_adapt_blob.c $(BM_DIR)/gen/cow_cut_blob.c \
            $(BM_DIR)/gen/cow_details_blob.c
$(BM_DIR)/obj/cow_%_blob.o: $(BM_DIR)/gen/cow_%_blob.c
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -c $< -o $@
# the runtime's own sizes for the static buffers (host helper, host runtime)
$(BM_DIR)/mem_bytes: ports/baremetal/mem_bytes.c runtime/include/sinew.h $(SN_LIB_FIXED)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) $(SN_INC) -o $@ $< $(SN_LIB_FIXED)
$(BM_DIR)/gen/%_mem.h: $(BUILD)/level/%.blob $(BM_DIR)/mem_bytes
	@mkdir -p $(dir $@)
	$(BM_DIR)/mem_bytes $< > $@.tmp || { rm -f $@.tmp; exit 1; }
	mv $@.tmp $@
# $(1) image, $(2) blob (cow_lod, cow_adapt), $(3) steps, $(4) name of the
# switch variable (det_main's K:L list; empty: no switch), $(5) shared 0/1,
# $(6) bench 0/1, $(7) more defines (SN_BM_DETAILS, SN_BM_ITERS)
define bm_level_image
$(BM_DIR)/obj/main_$(1).o: ports/baremetal/main_level.c $(PORT_HDRS) ports/baremetal/semihost.h \
        $(BM_DIR)/gen/$(2)_mem.h ports/baremetal/baremetal.mk
	@mkdir -p $$(dir $$@)
	$(BM_CC) $(BM_CFLAGS) -include $(BM_DIR)/gen/$(2)_mem.h -DSN_BM_BLOB=sinew_$(2)_blob \
	    -DSN_BM_BLOB_SIZE=sinew_$(2)_blob_size -DSN_BM_STEPS=$(3) $(if $(4),-DSN_BM_LOD=$(subst :,$(comma),$($(4)))) \
	    -DSN_BM_SHARED=$(5) -DSN_BM_BENCH=$(if $(6),$(6),0) $(7) -c $$< -o $$@
$(BM_DIR)/$(1).elf: $(BM_DIR)/obj/main_$(1).o $(BM_OBJS) $(BM_DIR)/obj/$(2)_blob.o \
        $(BM_DIR)/obj/cow_clip.o ports/baremetal/an386.ld
	$(BM_CC) $(BM_LDFLAGS) -Wl,-Map,$$@.map -o $$@ $$(filter %.o,$$^)
endef
$(eval $(call bm_level_image,level_lod,cow_lod,$(BM_STEPS),BM_LEVEL_LOD,0))
$(eval $(call bm_level_image,level_adapt,cow_adapt,$(BM_STEPS),BM_LEVEL_LOD,1))
$(eval $(call bm_level_image,level_lod_slice,cow_lod,$(BM_SLICE_STEPS),BM_SLICE_LOD,0))
$(eval $(call bm_level_image,level_adapt_slice,cow_adapt,$(BM_SLICE_STEPS),BM_SLICE_LOD,1))
$(eval $(call bm_level_image,level_cut,cow_cut,$(BM_CUT_STEPS),BM_LEVEL_CUT,0))
$(eval $(call bm_level_image,level_cut_slice,cow_cut,$(BM_SLICE_STEPS),BM_SLICE_LOD,0))
BM_DETAILS_DEFS = -DSN_BM_DETAILS=$(BM_DETAILS_N) -DSN_BM_ITERS=$(BM_DETAILS_ITERS)
$(eval $(call bm_level_image,level_details,cow_details,$(BM_DETAILS_STEPS),,0,0,$(BM_DETAILS_DEFS)))
$(eval $(call bm_level_image,level_details_slice,cow_details,$(BM_DETAILS_SLICE_STEPS),,0,0,$(BM_DETAILS_DEFS)))
# the details chosen by the runtime (stage 3, det_main --detail-adapt): the
# full run against details_adapt_trot_fixed (make determinism-m4), the slice
# against x86-64 det_main's same steps (tests/scripts/test_details_adapt.sh)
$(eval $(call bm_level_image,level_dadapt,cow_details,$(BM_DETAILS_STEPS),,0,0,-DSN_BM_DETAIL_ADAPT=1))
$(eval $(call bm_level_image,level_dadapt_slice,cow_details,$(BM_DETAILS_SLICE_STEPS),,0,0,-DSN_BM_DETAIL_ADAPT=1))
# timed (make bench-baremetal-level): instructions per step on each level
$(eval $(call bm_level_image,bench_level_lod,cow_lod,$(BM_STEPS),BM_LEVEL_LOD,0,1))
$(eval $(call bm_level_image,bench_level_adapt,cow_adapt,$(BM_STEPS),BM_LEVEL_LOD,1,1))
$(eval $(call bm_level_image,bench_level_cut,cow_cut,$(BM_CUT_STEPS),BM_LEVEL_CUT,0,1))
$(eval $(call bm_level_image,bench_level_details,cow_details,$(BM_DETAILS_STEPS),,0,1,$(BM_DETAILS_DEFS)))
.PHONY: bench-baremetal-level
bench-baremetal-level: $(BM_DIR)/bench_level_lod.elf $(BM_DIR)/bench_level_adapt.elf $(BM_DIR)/bench_level_cut.elf \
                       $(BM_DIR)/bench_level_details.elf
	for i in lod adapt; do echo "== level_$$i (1000 steps, switches $(BM_LEVEL_LOD), qemu -icount shift=0)"; \
	    timeout 900 $(BM_QEMU_ICOUNT) -kernel $(BM_DIR)/bench_level_$$i.elf < /dev/null 2>&1 | grep -E '^(insns|hash|saturations)' || exit 1; done
	echo "== level_cut ($(BM_CUT_STEPS) steps, switches $(BM_LEVEL_CUT), qemu -icount shift=0)"; \
	    timeout 900 $(BM_QEMU_ICOUNT) -kernel $(BM_DIR)/bench_level_cut.elf < /dev/null 2>&1 | grep -E '^(insns|hash|saturations)'
	echo "== level_details ($(BM_DETAILS_STEPS) steps, $(BM_DETAILS_N) details, $(BM_DETAILS_ITERS) iterations, qemu -icount shift=0)"; \
	    timeout 900 $(BM_QEMU_ICOUNT) -kernel $(BM_DIR)/bench_level_details.elf < /dev/null 2>&1 | grep -E '^(insns|hash|saturations)'
BM_LEVEL_IMAGES = $(foreach i,level_lod level_adapt level_lod_slice level_adapt_slice level_cut level_cut_slice \
                    level_details level_details_slice level_dadapt level_dadapt_slice,$(BM_DIR)/$(i).elf)
BM_QEMU_ICOUNT = qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
                 -semihosting-config enable=on,target=native -icount shift=0,sleep=off
.PHONY: print-bm-level determinism-m4
determinism-m4:   # the full runs alone, against tests/expected_hashes.txt
	BUILD=$(BUILD) sh ports/baremetal/determinism_m4.sh
.PHONY: print-bm-level
print-bm-level:   # for test_determinism.sh: steps and switches of the runs (full, slice, cut, details)
	@echo $(BM_STEPS) $(BM_LEVEL_LOD) $(BM_SLICE_STEPS) $(BM_SLICE_LOD) $(BM_CUT_STEPS) $(BM_LEVEL_CUT) \
	    $(BM_DETAILS_STEPS) $(BM_DETAILS_SLICE_STEPS) $(BM_DETAILS_N) $(BM_DETAILS_ITERS)

BM_IMAGES = $(BM_DIR)/sinew_cow.elf $(BM_DIR)/bench_cow.elf $(BM_DIR)/sinew_limb.elf $(BM_DIR)/bench_limb.elf
ports-baremetal: $(BM_IMAGES) $(BM_LEVEL_IMAGES)

# test_nofloat.sh: the float flavour of a runtime object is its positive control
# (one is enough to show the check sees soft-float helpers: sn_math.c, the
# arithmetic core, references 11; all 24 objects cost 11 CPU-s to build)
.PHONY: bm-float-objs print-port-sn-srcs print-sn-libs print-bm-float-control
BM_FLOAT_CONTROL = runtime/src/sn_math.c
$(BM_DIR)/obj-float/%.o: %.c $(PORT_HDRS)
	@mkdir -p $(dir $@)
	$(BM_CC) $(BM_CFLAGS) -DSN_FLOAT -c $< -o $@
bm-float-objs: $(patsubst %.c,$(BM_DIR)/obj-float/%.o,$(BM_FLOAT_CONTROL))
print-bm-float-control:
	@echo $(BM_FLOAT_CONTROL)
print-port-sn-srcs:
	@echo $(PORT_SN_SRCS)
print-sn-libs:
	@echo $(SN_LIB_FIXED) $(SN_LIB_FLOAT)

bench-baremetal:
	BUILD=$(BUILD) sh ports/baremetal/bench.sh
bench: bench-baremetal
.PHONY: profile-baremetal profile-m4 print-prof-m4-steps
# Cortex-M4 instructions per step per function (QEMU TCG plugin, ~10 s);
# PROF_M4_ASSET=limb for the limb, PROF_M4_LINES=N for the N hottest source lines
profile-m4 profile-baremetal:
	BUILD=$(BUILD) sh ports/baremetal/profile_m4.sh $(if $(PROF_M4_ASSET),$(PROF_M4_ASSET),cow) $(PROF_M4_LINES)
print-prof-m4-steps:
	@echo $(PROF_M4_STEPS)

# ---- hosted determinism drivers (det_main) for every compiler/CPU ----
CROSS_DIR   = $(BUILD)/cross
DET_MAIN_SRCS = ports/cross/det_main.c $(PORT_COMMON)
# no -g: the drivers are run, never debugged (-g is a fifth of their compile
# time and changes no code; rebuild one with -g by hand to trace a mismatch)
DET_CFLAGS  = $(PORT_WARN) $(PORT_INC)
# the runtime as objects per driver, $(CROSS_DIR)/obj/<name>/: compiled once
# with the driver's compiler and code flags (-static, a link flag, left out),
# and linked by the driver and by the kernel test of the same path
# (tests/kernels.mk: kernels_avx2 ... link these instead of compiling the
# runtime again); each C file is its own translation unit either way, so the
# code is the one a single compile-and-link command made
det_rt_objs = $(patsubst %.c,$(CROSS_DIR)/obj/$(1)/%.o,$(PORT_SN_SRCS))
# $(1) name, $(2) compiler, $(3) flags (the float drivers: -DSN_FLOAT -ffp-contract=off too)
define det_rt_rule
$(CROSS_DIR)/obj/$(1)/%.o: %.c $(PORT_HDRS)
	@mkdir -p $$(@D)
	$(2) $(DET_CFLAGS) $(filter-out -static,$(3)) -c $$< -o $$@
endef
# $(1) name, $(2) compiler, $(3) flags
define det_driver
DET_CC_$(1) = $(firstword $(2))
$(eval $(call det_rt_rule,$(1),$(2),$(3)))
$(CROSS_DIR)/det_$(1): $(DET_MAIN_SRCS) $(call det_rt_objs,$(1)) $(PORT_HDRS) $(COW_BLOB_C)
	@mkdir -p $$(dir $$@)
	$(2) $(DET_CFLAGS) $(3) -DSN_DET_BLOB=sinew_cow_blob -DSN_DET_BLOB_SIZE=sinew_cow_blob_size \
	    -o $$@ $(DET_MAIN_SRCS) $(call det_rt_objs,$(1)) $(COW_BLOB_C)
endef
$(eval $(call det_driver,x86_64-gcc-O0,gcc,-O0))
$(eval $(call det_driver,x86_64-gcc-O2,gcc,-O2))
$(eval $(call det_driver,x86_64-clang-O2,clang,-O2))
$(eval $(call det_driver,i686-gcc-O2,i686-linux-gnu-gcc,-O2 -static))
$(eval $(call det_driver,armhf-gcc-O2,arm-linux-gnueabihf-gcc,-O2 -static))
$(eval $(call det_driver,mips-be-gcc-O2,mips-linux-gnu-gcc,-O2 -static))
# clang as a cross compiler, on the cross gcc's sysroot and libgcc
$(eval $(call det_driver,i686-clang-O2,clang --target=i686-linux-gnu,-O2 -static))
$(eval $(call det_driver,mips-be-clang-O2,clang --target=mips-linux-gnu,-O2 -static))
# SIMD kernel paths (runtime/src/sn_kernels.h): the plain x86_64 drivers above
# build the SSE2 baseline (scalar kernels), these the others; aarch64 = NEON
$(eval $(call det_driver,x86_64-gcc-O2-scalar,gcc,-O2 -DSN_SIMD_SCALAR))
$(eval $(call det_driver,x86_64-gcc-O2-avx2,gcc,-O2 -mavx2))
$(eval $(call det_driver,x86_64-gcc-O0-avx2,gcc,-O0 -mavx2))
$(eval $(call det_driver,x86_64-clang-O2-avx2,clang,-O2 -mavx2))
$(eval $(call det_driver,x86_64-gcc-O2-avx512,gcc,-O2 -mavx2 -mavx512f -mavx512vl))
$(eval $(call det_driver,x86_64-clang-O2-avx512,clang,-O2 -mavx2 -mavx512f -mavx512vl))
$(eval $(call det_driver,armhf-gcc-O2-neon,arm-linux-gnueabihf-gcc,-O2 -mfpu=neon -static))
$(eval $(call det_driver,aarch64-gcc-O2,aarch64-linux-gnu-gcc,-O2 -static))
$(eval $(call det_driver,aarch64-gcc-O2-scalar,aarch64-linux-gnu-gcc,-O2 -DSN_SIMD_SCALAR -static))
$(eval $(call det_driver,aarch64-clang-O2,clang --target=aarch64-linux-gnu,-O2 -static))
# float flavour: desktop only, no FMA contraction so -O0/-O2 and gcc/clang
# agree; the blob comes from the file (the target builds it too)
define det_float
DET_CC_$(1) = $(firstword $(2))
$(eval $(call det_rt_rule,$(1),$(2),$(3) -DSN_FLOAT -ffp-contract=off))
$(CROSS_DIR)/det_$(1): $(DET_MAIN_SRCS) $(call det_rt_objs,$(1)) $(PORT_HDRS) $(COW_FLOAT_BLOB)
	@mkdir -p $$(dir $$@)
	$(2) $(DET_CFLAGS) $(3) -DSN_FLOAT -ffp-contract=off -o $$@ $(DET_MAIN_SRCS) $(call det_rt_objs,$(1))
endef
$(eval $(call det_float,float-gcc-O0,gcc,-O0))
$(eval $(call det_float,float-gcc-O2,gcc,-O2))
$(eval $(call det_float,float-clang-O2,clang,-O2))
# the float SIMD kernels (AVX2, aarch64 NEON: sn_kernels_fsimd.c) compute the
# scalar reference's floats, so every path gives the one float hash (clang's
# -mavx512f implies FMA: -ffp-contract=off, as above, keeps the scalar code
# unfused; the kernels' intrinsics never fuse; GCC 12's SLP fused sn_qmul's
# float sums even so, sn_math.c)
$(eval $(call det_float,float-gcc-O2-avx2,gcc,-O2 -mavx2))
$(eval $(call det_float,float-clang-O2-avx2,clang,-O2 -mavx2))
$(eval $(call det_float,float-clang-O2-avx512,clang,-O2 -mavx2 -mavx512f -mavx512vl))
$(eval $(call det_float,float-gcc-O2-avx512,gcc,-O2 -mavx2 -mavx512f -mavx512vl))
$(eval $(call det_float,float-aarch64-gcc-O2,aarch64-linux-gnu-gcc,-O2 -static))
$(eval $(call det_float,float-aarch64-gcc-O2-scalar,aarch64-linux-gnu-gcc,-O2 -DSN_SIMD_SCALAR -static))
$(eval $(call det_float,float-aarch64-clang-O2,clang --target=aarch64-linux-gnu,-O2 -static))

# every driver whose compiler is installed (make deps installs them all)
CROSS_HAVE = $(foreach d,x86_64-gcc-O2:gcc x86_64-clang-O2:clang i686-gcc-O2:i686-linux-gnu-gcc \
               armhf-gcc-O2:arm-linux-gnueabihf-gcc mips-be-gcc-O2:mips-linux-gnu-gcc \
               aarch64-gcc-O2:aarch64-linux-gnu-gcc armhf-gcc-O2-neon:arm-linux-gnueabihf-gcc,\
               $(if $(shell command -v $(word 2,$(subst :, ,$(d))) 2>/dev/null),$(CROSS_DIR)/det_$(word 1,$(subst :, ,$(d)))))
ports-cross: $(CROSS_HAVE)
ports: ports-baremetal ports-cross

# ---- what make test's port scripts run, built by test-build (-j2 beside
# everything else) so that the scripts only run: the determinism slice
# (tests/scripts/test_determinism.sh reads DET_SLICE: one build per axis),
# the Cortex-M4 images of test_baremetal.sh and of test_determinism.sh's
# level slice, and the objects of test_nofloat.sh.
# A driver whose compiler is missing is left out here; the script reports it.
DET_SLICE = cortex-m4-qemu mips-be-gcc-O2 armhf-gcc-O2-neon aarch64-gcc-O2 x86_64-gcc-O0 \
            x86_64-gcc-O2-avx2 x86_64-clang-O2 float-gcc-O2 float-clang-O2 \
            float-gcc-O2-avx2 float-aarch64-gcc-O2
.PHONY: print-det-slice
print-det-slice:
	@echo $(DET_SLICE)
TEST_DEPS += $(foreach d,$(filter-out cortex-m4-qemu,$(DET_SLICE)),\
               $(if $(shell command -v $(DET_CC_$(d)) 2>/dev/null),$(CROSS_DIR)/det_$(d)))
ifneq ($(shell command -v $(BM_CC) 2>/dev/null),)
TEST_DEPS += $(BM_DIR)/sinew_cow.elf $(BM_DIR)/sinew_limb.elf $(BM_DIR)/bad_blob.elf $(BM_DIR)/test_kernels.elf \
             $(BM_DIR)/level_lod_slice.elf $(BM_DIR)/level_adapt_slice.elf $(BM_DIR)/level_cut_slice.elf \
             $(BM_DIR)/level_details_slice.elf $(BM_DIR)/level_dadapt_slice.elf $(patsubst %.c,$(BM_DIR)/obj-float/%.o,$(BM_FLOAT_CONTROL))
endif
