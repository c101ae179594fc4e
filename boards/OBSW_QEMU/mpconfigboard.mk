# obsw on an emulated Cortex-M3 (QEMU mps2-an385): the MPS2_AN385 board of the qemu port with
# the Pyboard's float (double precision, in software), its application heap (MICROPY_HEAP_SIZE) and C stack
# limit (OBSW_STACK_LIMIT; both set by tools/firmware.py from the Pyboard ELF) and a
# /flash-like filesystem kept outside the heap.
QEMU_ARCH = arm
QEMU_MACHINE = mps2-an385

CFLAGS += -mthumb -mcpu=cortex-m3 -mfloat-abi=soft
CFLAGS += -DQEMU_SOC_MPS2
CFLAGS += -DMICROPY_HW_MCU_NAME='"Cortex-M3"'
# mount the RAM filesystem at every (soft) reset, as a Pyboard mounts /flash
CFLAGS += '-DMICROPY_PORT_INIT_FUNC=do { extern void obsw_qemu_boot(void); obsw_qemu_boot(); } while (0)'

# the Pyboard's: _estack - _sstack (16 KiB) less the stm32 port's 1 KiB check margin; the qemu
# port's main.c sets 10 KiB, obsw_qemu_boot() raises it at every (soft) reset
OBSW_STACK_LIMIT ?= 15360
CFLAGS += -DOBSW_STACK_LIMIT=$(OBSW_STACK_LIMIT)

LDSCRIPT = mcu/arm/mps2.ld

SRC_BOARD_O = shared/runtime/gchelper_native.o shared/runtime/gchelper_thumb2.o

MPY_CROSS_FLAGS += -march=armv7m

MICROPY_VFS_LFS2 = 1
MICROPY_FLOAT_IMPL = double
USER_C_MODULES = $(BOARD_DIR)/cmodules
FROZEN_MANIFEST ?= $(BOARD_DIR)/../../manifests/qemu.py

# cryptolib on mbed TLS (see the fragment)
include $(BOARD_DIR)/../common/cryptolib.mk
