# The kernel test (tests/test_runtime_kernels.c) on the SIMD paths the
# default build does not compile: x86-64 AVX2 and aarch64 NEON, each flavour
# (the float ones are sn_kernels_fsimd.c). The test compiled per path, linked
# with the runtime objects of the determinism driver of the same path
# (ports/baremetal/baremetal.mk det_rt_objs: gcc -O2 [-mavx2] [-DSN_FLOAT
# -ffp-contract=off, which -std=c99 already implies]), which make test builds
# anyway: the runtime is not compiled a second time for the test.
# Run by tests/scripts/test_kernel_paths.sh (AVX2 where the CPU has it,
# aarch64 under qemu-aarch64). A missing compiler leaves its binaries out.
KP_DIR  = $(BUILD)/tests/kpaths
KP_DEPS = tests/test_runtime_kernels.c $(SN_TEST_HDRS)
KP_CFLAGS = -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 $(SN_INC) -Iruntime/src -Itests
# $(1) binary, $(2) compiler, $(3) flags, $(4) driver whose runtime objects it links
define kp_rule
$(KP_DIR)/$(1): $(KP_DEPS) $(call det_rt_objs,$(4))
	@mkdir -p $$(@D)
	$(2) $(KP_CFLAGS) $(3) -o $$@ tests/test_runtime_kernels.c $(call det_rt_objs,$(4)) -lm
endef
$(eval $(call kp_rule,kernels_avx2,$(CC),-mavx2,x86_64-gcc-O2-avx2))
$(eval $(call kp_rule,kernels_avx2_float,$(CC),-mavx2 -DSN_FLOAT,float-gcc-O2-avx2))
$(eval $(call kp_rule,kernels_avx512,$(CC),-mavx2 -mavx512f -mavx512vl,x86_64-gcc-O2-avx512))
$(eval $(call kp_rule,kernels_avx512_float,$(CC),-mavx2 -mavx512f -mavx512vl -DSN_FLOAT,float-gcc-O2-avx512))
$(eval $(call kp_rule,kernels_aarch64,aarch64-linux-gnu-gcc,-static,aarch64-gcc-O2))
$(eval $(call kp_rule,kernels_aarch64_float,aarch64-linux-gnu-gcc,-static -DSN_FLOAT,float-aarch64-gcc-O2))
TEST_DEPS += $(KP_DIR)/kernels_avx2 $(KP_DIR)/kernels_avx2_float \
             $(if $(shell command -v aarch64-linux-gnu-gcc 2>/dev/null),$(KP_DIR)/kernels_aarch64 $(KP_DIR)/kernels_aarch64_float)
