# integration.mk -- Sinew in other people's builds (see also CMakeLists.txt).
#   make install PREFIX=/opt/sinew   header, libsinew.a, libsinew_float.a,
#                                    sinew-bake, pkg-config files sinew.pc and
#                                    sinew-float.pc (Cflags -DSN_FLOAT)
#   make amalgamation                $(BUILD)/amalgamation/sinew.c + sinew.h:
#                                    the runtime as one file (tools/amalgamate.sh)
# Inputs from other fragments: SN_SRCS, SN_HDRS, SN_LIB_FIXED, SN_LIB_FLOAT
# (runtime.mk), BAKE (tools.mk). The suite's check is
# tests/scripts/test_integration.sh (make test: libraries; make integration-full: all).
PREFIX       ?= /usr/local
DESTDIR      ?=
BINDIR       ?= $(PREFIX)/bin
LIBDIR       ?= $(PREFIX)/lib
INCLUDEDIR   ?= $(PREFIX)/include
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
SN_VERSION    = $(shell sed -n 's/^\#define SN_VERSION_MAJOR \([0-9]*\).*/\1/p' runtime/include/sinew.h).$(shell sed -n 's/^\#define SN_VERSION_MINOR \([0-9]*\).*/\1/p' runtime/include/sinew.h)
# pkg-config paths: relative to ${prefix} when under PREFIX
SN_PC_SED = -e 's|@PC_PREFIX@|$(PREFIX)|' \
            -e 's|@PC_LIBDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(LIBDIR))|' \
            -e 's|@PC_INCLUDEDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(INCLUDEDIR))|' \
            -e 's|@PC_VERSION@|$(SN_VERSION)|'

.PHONY: install amalgamation sn-amal-sources-force
install: $(SN_LIB_FIXED) $(SN_LIB_FLOAT) $(BAKE) runtime/include/sinew.h cmake/sinew.pc.in cmake/sinew-float.pc.in
	mkdir -p $(DESTDIR)$(BINDIR) $(DESTDIR)$(LIBDIR) $(DESTDIR)$(INCLUDEDIR) $(DESTDIR)$(PKGCONFIGDIR)
	cp runtime/include/sinew.h $(DESTDIR)$(INCLUDEDIR)/sinew.h
	chmod 644 $(DESTDIR)$(INCLUDEDIR)/sinew.h
	cp $(SN_LIB_FIXED) $(SN_LIB_FLOAT) $(DESTDIR)$(LIBDIR)/
	cd $(DESTDIR)$(LIBDIR) && chmod 644 $(notdir $(SN_LIB_FIXED) $(SN_LIB_FLOAT))
	cp $(BAKE) $(DESTDIR)$(BINDIR)/sinew-bake
	chmod 755 $(DESTDIR)$(BINDIR)/sinew-bake
	sed $(SN_PC_SED) cmake/sinew.pc.in > $(DESTDIR)$(PKGCONFIGDIR)/sinew.pc
	sed $(SN_PC_SED) cmake/sinew-float.pc.in > $(DESTDIR)$(PKGCONFIGDIR)/sinew-float.pc
	@echo "installed Sinew $(SN_VERSION) in $(DESTDIR)$(PREFIX) (pkg-config: sinew, sinew-float)"

# ---- amalgamation: regenerated when a source changes, appears or goes ----
AMAL_DIR = $(BUILD)/amalgamation
amalgamation: $(AMAL_DIR)/sinew.c
# the source list as a file that changes only when the list does
$(AMAL_DIR)/sources: sn-amal-sources-force
	@mkdir -p $(@D)
	@echo '$(sort $(SN_SRCS))' | cmp -s - $@ || echo '$(sort $(SN_SRCS))' > $@
$(AMAL_DIR)/sinew.c: tools/amalgamate.sh $(AMAL_DIR)/sources $(SN_SRCS) $(SN_HDRS)
	sh tools/amalgamate.sh $(AMAL_DIR) $(SN_SRCS)
TEST_DEPS += $(AMAL_DIR)/sinew.c

# make test runs tests/scripts/test_integration.sh with the CMake project's
# libraries only; `make integration-full` also builds its sinew-bake and
# players from scratch and checks them against make's (the cow baked byte for
# byte, sinew-play's hash), the installed sinew-bake and sinew::bake.
.PHONY: integration-full
integration-full:
	SN_INTEGRATION_FULL=1 BUILD=$(BUILD) sh tests/scripts/test_integration.sh

# for tests/scripts/test_integration.sh: the names this build uses
.PHONY: print-integration-vars
print-integration-vars:
	@echo $(SN_LIB_FIXED) $(SN_LIB_FLOAT) $(BAKE) $(AMAL_DIR)
