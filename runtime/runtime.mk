# runtime build fragment: the shipping library in two flavours.
#   $(SN_LIB_FIXED)  build/libsinew.a        integers only (default)
#   $(SN_LIB_FLOAT)  build/libsinew_float.a  -DSN_FLOAT
# Sources: every runtime/src/*.c (wildcard), compiled warning-clean with
# $(SN_WARN); objects in $(BUILD)/runtime/{fixed,float}/.
SN_INC   = -Iruntime/include
# SIMD path of the kernels (runtime/src/sn_kernels.h), chosen at build time:
#   auto    what the compiler targets (x86-64: AVX2 if -mavx2/-march says so,
#           else the scalar reference; aarch64: NEON; Cortex-M4: DSP)
#   scalar  the portable reference everywhere
#   sse2    x86-64 baseline (no AVX2: the scalar reference, see NUMERICS.md)
#   avx2 / avx512   x86-64 (-mavx2 / -mavx512f -mavx512vl)
#   neon    ARM NEON (armhf: -mfpu=neon; aarch64 has it by default)
# Every path gives the same state hash in each flavour (test_determinism.sh;
# float: AVX2 and aarch64 compute the scalar float's bits, NUMERICS.md).
SIMD ?= auto
SN_SIMD_FLAGS_auto   =
SN_SIMD_FLAGS_scalar = -DSN_SIMD_SCALAR
SN_SIMD_FLAGS_sse2   = -mno-avx2
SN_SIMD_FLAGS_avx2   = -mavx2
SN_SIMD_FLAGS_avx512 = -mavx2 -mavx512f -mavx512vl
SN_SIMD_FLAGS_neon   = $(if $(findstring aarch64,$(CC)),,-mfpu=neon)
SN_SIMD_FLAGS = $(SN_SIMD_FLAGS_$(SIMD))
ifeq ($(filter $(SIMD),auto scalar sse2 avx2 avx512 neon),)
$(error SIMD=$(SIMD): one of auto scalar sse2 avx2 avx512 neon)
endif
SN_WARN  = $(WARN) -Wvla -Wshadow
SN_SRCS  = $(wildcard runtime/src/*.c)
SN_HDRS  = runtime/include/sinew.h $(wildcard runtime/src/*.h)
SN_OBJS_FIXED = $(patsubst runtime/src/%.c,$(BUILD)/runtime/fixed/%.o,$(SN_SRCS))
SN_OBJS_FLOAT = $(patsubst runtime/src/%.c,$(BUILD)/runtime/float/%.o,$(SN_SRCS))
SN_LIB_FIXED = $(BUILD)/libsinew.a
SN_LIB_FLOAT = $(BUILD)/libsinew_float.a
AR ?= ar

all: $(SN_LIB_FIXED) $(SN_LIB_FLOAT)

$(BUILD)/runtime/fixed/%.o: runtime/src/%.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) $(SN_INC) -c $< -o $@

$(BUILD)/runtime/float/%.o: runtime/src/%.c $(SN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) -DSN_FLOAT $(SN_INC) -c $< -o $@

$(SN_LIB_FIXED): $(SN_OBJS_FIXED)
	@rm -f $@
	$(AR) rcs $@ $^

$(SN_LIB_FLOAT): $(SN_OBJS_FLOAT)
	@rm -f $@
	$(AR) rcs $@ $^
# the float objects' compile line, for tests/scripts/test_runtime_rules.sh
# (it checks these objects instead of compiling its own gcc float set when
# this line is its own, -g aside)
.PHONY: print-sn-float-cc
print-sn-float-cc:
	@echo '$(CC) $(SN_WARN) $(CFLAGS) $(SN_SIMD_FLAGS) -DSN_FLOAT $(SN_INC)'

# ---- runtime tests: each built fixed and float (suffix _float) ----
SN_TCFLAGS = -std=c99 -Wall -Wextra -Wpedantic -Werror $(CFLAGS) $(SN_INC) -Iruntime/src -Itests
SN_TEST_HDRS = $(SN_HDRS) tests/sn_test.h tests/fuzz/sn_tblob.h
SN_TESTS = math blob rig kernels
# the kernels test includes inline kernels (sn_kernels_ic.h): built for the library's SIMD path
SN_TCFLAGS_kernels = $(SN_SIMD_FLAGS)

define SN_TEST_RULE
$(BUILD)/tests/test_runtime_$(1): tests/test_runtime_$(1).c $(SN_TEST_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $$(@D)
	$(CC) $(SN_TCFLAGS) $(SN_TCFLAGS_$(1)) -o $$@ $$< $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_$(1)_float: tests/test_runtime_$(1).c $(SN_TEST_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $$(@D)
	$(CC) $(SN_TCFLAGS) $(SN_TCFLAGS_$(1)) -DSN_FLOAT -o $$@ $$< $(SN_LIB_FLOAT) -lm
endef
$(foreach t,$(SN_TESTS),$(eval $(call SN_TEST_RULE,$(t))))
TEST_BINS += $(foreach t,$(SN_TESTS),$(BUILD)/tests/test_runtime_$(t) $(BUILD)/tests/test_runtime_$(t)_float)
# segment meshes: with the double reference tests/reference/segref.c
SN_SEG_TEST_DEPS = tests/test_runtime_segment.c tests/reference/segref.c tests/reference/segref.h $(SN_TEST_HDRS)
$(BUILD)/tests/test_runtime_segment: $(SN_SEG_TEST_DEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ tests/test_runtime_segment.c tests/reference/segref.c $(SN_LIB_FIXED) -lm
$(BUILD)/tests/test_runtime_segment_float: $(SN_SEG_TEST_DEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ tests/test_runtime_segment.c tests/reference/segref.c $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_segment $(BUILD)/tests/test_runtime_segment_float
# the float initial-residual fold in torn states (float only: fixed does not fold)
$(BUILD)/tests/test_runtime_fold_float: tests/test_runtime_fold.c $(SN_TEST_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -DSN_FLOAT -o $@ tests/test_runtime_fold.c $(SN_LIB_FLOAT) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_fold_float

# ---- constant cost: the probe tests/scripts/test_cost.sh runs under callgrind ----
$(BUILD)/tests/cost_probe: tests/cost_probe.c $(SN_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< $(SN_LIB_FIXED) -lm
TEST_DEPS += $(BUILD)/tests/cost_probe

# ---- hostile blobs (tests/fuzz): the runtime sources compiled into the
# fuzzer with ASan + UBSan; _ck keeps the checksum (every flip must fail) ----
SN_FUZZ_CFLAGS = -std=c99 -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined \
                 -fno-sanitize-recover=all $(SN_INC) -Iruntime/src -Itests/fuzz
SN_FUZZ_DEPS = tests/fuzz/fuzz_blob.c tests/fuzz/sn_tblob.h tests/fuzz/sn_thostile.h $(SN_HDRS)
# the runtime as objects per build (-j2 compiles them in parallel): fuzz and
# fuzz_ck share all but sn_blob.c, the only source SN_VALIDATE_NO_CHECKSUM reaches
SN_FUZZ_OBJ = $(BUILD)/fuzz-obj
SN_FUZZ_DEFS_fixed =
SN_FUZZ_DEFS_nock  = -DSN_VALIDATE_NO_CHECKSUM
SN_FUZZ_DEFS_float = -DSN_FLOAT -DSN_VALIDATE_NO_CHECKSUM
SN_FUZZ_DEFS_range = -DSN_VALIDATE_NO_CHECKSUM -DSN_RANGE_CHECK
define SN_FUZZ_OBJ_RULE
$(SN_FUZZ_OBJ)/$(1)/%.o: runtime/src/%.c $(SN_HDRS)
	@mkdir -p $$(@D)
	$(CC) $(SN_FUZZ_CFLAGS) $(SN_FUZZ_DEFS_$(1)) -c $$< -o $$@
endef
$(foreach f,fixed nock float range,$(eval $(call SN_FUZZ_OBJ_RULE,$(f))))
sn_fuzz_objs = $(patsubst runtime/src/%.c,$(SN_FUZZ_OBJ)/$(1)/%.o,$(SN_SRCS))
SN_FUZZ_OBJS_ck    = $(call sn_fuzz_objs,fixed)
SN_FUZZ_OBJS_nock  = $(filter-out %/sn_blob.o,$(SN_FUZZ_OBJS_ck)) $(SN_FUZZ_OBJ)/nock/sn_blob.o
SN_FUZZ_OBJS_float = $(call sn_fuzz_objs,float)
SN_FUZZ_OBJS_range = $(call sn_fuzz_objs,range)
$(BUILD)/tests/test_runtime_fuzz: $(SN_FUZZ_DEPS) $(SN_FUZZ_OBJS_nock)
	@mkdir -p $(@D)
	$(CC) $(SN_FUZZ_CFLAGS) -DSN_VALIDATE_NO_CHECKSUM -DSN_FUZZ_RANDOM_ONLY -o $@ tests/fuzz/fuzz_blob.c $(SN_FUZZ_OBJS_nock) -lm
# the range-checking build's checks fire (no library: sn_internal.h inline code)
$(BUILD)/tests/test_runtime_range: tests/test_runtime_range.c $(SN_TEST_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SN_TCFLAGS) -o $@ $< -lm
TEST_BINS += $(BUILD)/tests/test_runtime_range
# the same hostile blobs through the range-checking build (every derived
# shift, conversion and int64 sum bound asserted: sn_internal.h SN_RANGE)
$(BUILD)/tests/test_runtime_fuzz_range: $(SN_FUZZ_DEPS) tests/fuzz/range_fail.c $(SN_FUZZ_OBJS_range)
	@mkdir -p $(@D)
	$(CC) $(SN_FUZZ_CFLAGS) -DSN_VALIDATE_NO_CHECKSUM -DSN_RANGE_CHECK -DSN_FUZZ_PER_SECTION=40 -o $@ tests/fuzz/fuzz_blob.c tests/fuzz/range_fail.c $(SN_FUZZ_OBJS_range) -lm
$(BUILD)/tests/test_runtime_fuzz_ck: $(SN_FUZZ_DEPS) $(SN_FUZZ_OBJS_ck)
	@mkdir -p $(@D)
	$(CC) $(SN_FUZZ_CFLAGS) -o $@ tests/fuzz/fuzz_blob.c $(SN_FUZZ_OBJS_ck) -lm
$(BUILD)/tests/test_runtime_fuzz_float: $(SN_FUZZ_DEPS) $(SN_FUZZ_OBJS_float)
	@mkdir -p $(@D)
	$(CC) $(SN_FUZZ_CFLAGS) -DSN_FLOAT -DSN_VALIDATE_NO_CHECKSUM -o $@ tests/fuzz/fuzz_blob.c $(SN_FUZZ_OBJS_float) -lm
TEST_BINS += $(BUILD)/tests/test_runtime_fuzz $(BUILD)/tests/test_runtime_fuzz_ck $(BUILD)/tests/test_runtime_fuzz_float \
             $(BUILD)/tests/test_runtime_fuzz_range
# the long campaign of the same hostile blobs (make test samples 100 random
# flips per section, the range build 40, and every bit of each section's
# first and last 4 bytes): 2000 per section and 16 bytes at each end, every build
# (--full: in make test the plain build test_runtime_fuzz runs only the cow's
# random flips, SN_FUZZ_RANDOM_ONLY; the range build runs its other cases
# with the same sanitizers plus the range checks)
FUZZ_BLOB_PER_SECTION ?= 2000
.PHONY: fuzz-blobs
fuzz-blobs: $(BUILD)/tests/test_runtime_fuzz $(BUILD)/tests/test_runtime_fuzz_float $(BUILD)/tests/test_runtime_fuzz_range \
            $(BUILD)/tests/test_runtime_fuzz_ck $(BUILD)/examples/cow.blob $(BUILD)/examples/cow_float.blob
	for t in test_runtime_fuzz test_runtime_fuzz_float test_runtime_fuzz_range test_runtime_fuzz_ck; do \
	    BUILD=$(BUILD) $(BUILD)/tests/$$t --full --per-section $(FUZZ_BLOB_PER_SECTION) --edge 16 || exit 1; done

# ---- make bench (runtime part): runtime/bench/bench.sh ----
# (--contact: the determinism driver's contact scenario, ports/cross/sn_det.c)
BENCH_DET = ports/cross/sn_det.c ports/common/sn_clip.c ports/common/sn_clip_pose.c
BENCH_DEPS = runtime/bench/bench.c runtime/bench/bench_common.h $(BENCH_DET) ports/cross/sn_det.h ports/common/sn_clip.h $(SN_HDRS)
$(BUILD)/bench/sn_bench: $(BENCH_DEPS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(SN_INC) -Iruntime/src -Iports/cross -Iports/common -o $@ $< $(BENCH_DET) $(SN_LIB_FIXED) -lm
$(BUILD)/bench/sn_bench_float: $(BENCH_DEPS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -DSN_FLOAT $(SN_INC) -Iruntime/src -Iports/cross -Iports/common -o $@ $< $(BENCH_DET) $(SN_LIB_FLOAT) -lm
# many instances sharing one blob (issue 15 item 5): runtime/bench/herd.c
$(BUILD)/bench/sn_herd: runtime/bench/herd.c runtime/bench/bench_common.h $(SN_HDRS) $(SN_LIB_FIXED)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(SN_INC) -o $@ $< $(SN_LIB_FIXED) -lm
$(BUILD)/bench/sn_herd_float: runtime/bench/herd.c runtime/bench/bench_common.h $(SN_HDRS) $(SN_LIB_FLOAT)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -DSN_FLOAT $(SN_INC) -o $@ $< $(SN_LIB_FLOAT) -lm
bench: $(BUILD)/bench/sn_herd $(BUILD)/bench/sn_herd_float
bench: $(BUILD)/bench/sn_bench $(BUILD)/bench/sn_bench_float $(BUILD)/examples/cow.blob $(BUILD)/examples/cow_float.blob \
       $(BUILD)/examples/beast.blob $(BUILD)/examples/beast_float.blob $(BUILD)/sinew-bake
	BUILD=$(BUILD) SIMD=$(SIMD) sh runtime/bench/bench.sh $(BUILD)
