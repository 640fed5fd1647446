# Sinew top-level Makefile. Out-of-tree build in $(BUILD).
# Each area owns a fragment: runtime/runtime.mk, tools/tools.mk,
# ports/desktop/desktop.mk, ports/baremetal/baremetal.mk, tests/tests.mk.
#   make          build runtime (fixed + float), host tool, players
#   make test     the whole suite; ends with "N passed, N failed"
#   make demo     bake the cow, play the bundled clips, write pictures
#   make bench    print speed / memory / instruction-count figures
#   make ports    cross-built images (bare metal, other architectures)
#   make clean
BUILD   ?= build
# an empty or root BUILD would write outputs under / and make clean remove it
ifeq ($(filter-out /,$(strip $(BUILD))),)
$(error BUILD must name a build directory (got '$(BUILD)'), e.g. BUILD=build)
endif
CC      ?= cc
OPT     ?= -O2
WARN     = -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Werror
CFLAGS  ?= $(OPT) -g
HOST_CFLAGS = -std=c99 -Wall -Wextra -Wpedantic -Werror $(CFLAGS)

.PHONY: all test bench demo clean ports
all:

include runtime/runtime.mk
include tools/tools.mk
include ports/desktop/desktop.mk
include ports/baremetal/baremetal.mk
include integration.mk
include tests/tests.mk
include tests/fuzz/fuzz.mk

clean:
	rm -rf $(BUILD)
