# obsw reconfiguration module, derived from boards/PYBV11/mpconfigboard.mk
MCU_SERIES = f4
CMSIS_MCU = STM32F405xx
AF_FILE = boards/stm32f405_af.csv
ifeq ($(USE_MBOOT),1)
# When using Mboot all the text goes together after the filesystem
LD_FILES = boards/stm32f405.ld boards/common_blifs.ld
TEXT0_ADDR = 0x08020000
else
# When not using Mboot the ISR text goes first, then the rest after the filesystem
LD_FILES = boards/stm32f405.ld boards/common_ifs.ld
TEXT0_ADDR = 0x08000000
TEXT1_ADDR = 0x08020000
endif

# MicroPython settings
MICROPY_VFS_LFS2 ?= 1
# Double-precision floats (in software: the F405's FPU is single precision). The application
# keeps time as float seconds since boot, as the host does: in single precision that float is
# 1 s coarse after 97 days of uptime and its 1 s periods collapse
# (tests/core/test_reconfig_uptime.py); in double it resolves a microsecond for 285 years.
MICROPY_FLOAT_IMPL = double

# The image freezes the reconfiguration application and the core modules it needs.
FROZEN_MANIFEST ?= $(BOARD_DIR)/../../manifests/reconfig.py

# cryptolib on mbed TLS (see the fragment)
include $(BOARD_DIR)/../common/cryptolib.mk
