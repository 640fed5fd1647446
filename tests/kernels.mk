# The kernel test (tests/test_runtime_kernels.c) on the SIMD paths the
# default build does not compile: x86-64 AVX2 and aarch64 NEON, each flavour
# (the float ones are sn_kernels_fsimd.c). One compile of the test with every
# runtime source per binary (no library per path); run by
# tests/scripts/test_kernel_paths.sh (AVX2 where the CPU has it, aarch64
# under qemu-aarch64). A missing compiler leaves its binaries out.
KP_DIR  = $(BUILD)/tests/kpaths
KP_SRCS = tests/test_runtime_kernels.c $(SN_SRCS)
KP_DEPS = $(KP_SRCS) $(SN_TEST_HDRS)
KP_CFLAGS = -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 $(SN_INC) -Iruntime/src -Itests
$(KP_DIR)/kernels_avx2: $(KP_DEPS)
	@mkdir -p $(@D)
	$(CC) $(KP_CFLAGS) -mavx2 -o $@ $(KP_SRCS) -lm
$(KP_DIR)/kernels_avx2_float: $(KP_DEPS)
	@mkdir -p $(@D)
	$(CC) $(KP_CFLAGS) -mavx2 -DSN_FLOAT -o $@ $(KP_SRCS) -lm
$(KP_DIR)/kernels_aarch64: $(KP_DEPS)
	@mkdir -p $(@D)
	aarch64-linux-gnu-gcc $(KP_CFLAGS) -static -o $@ $(KP_SRCS) -lm
$(KP_DIR)/kernels_aarch64_float: $(KP_DEPS)
	@mkdir -p $(@D)
	aarch64-linux-gnu-gcc $(KP_CFLAGS) -static -DSN_FLOAT -o $@ $(KP_SRCS) -lm
TEST_DEPS += $(KP_DIR)/kernels_avx2 $(KP_DIR)/kernels_avx2_float \
             $(if $(shell command -v aarch64-linux-gnu-gcc 2>/dev/null),$(KP_DIR)/kernels_aarch64 $(KP_DIR)/kernels_aarch64_float)
