// obsw_qemu: the board support of the QEMU board. disk() is a bytearray over a static buffer
// (outside the GC heap, like a Pyboard's internal flash) that frozen _boot.py mounts as a
// littlefs at "/"; obsw_qemu_boot() gives Python the Pyboard's C stack limit and runs _boot.py
// at every (soft) reset.
#include "py/cstack.h"
#include "py/runtime.h"
#include "shared/runtime/pyexec.h"

#define OBSW_DISK_BYTES (256 * 1024)

static uint8_t obsw_disk[OBSW_DISK_BYTES] __attribute__((aligned(4)));

static mp_obj_t obsw_qemu_disk(void) {
    return mp_obj_new_bytearray_by_ref(sizeof(obsw_disk), obsw_disk);
}
static MP_DEFINE_CONST_FUN_OBJ_0(obsw_qemu_disk_obj, obsw_qemu_disk);

static const mp_rom_map_elem_t obsw_qemu_globals_table[] = {
    { MP_ROM_QSTR(MP_QSTR___name__), MP_ROM_QSTR(MP_QSTR_obsw_qemu) },
    { MP_ROM_QSTR(MP_QSTR_disk), MP_ROM_PTR(&obsw_qemu_disk_obj) },
};
static MP_DEFINE_CONST_DICT(obsw_qemu_globals, obsw_qemu_globals_table);

const mp_obj_module_t obsw_qemu_module = {
    .base = { &mp_type_module },
    .globals = (mp_obj_dict_t *)&obsw_qemu_globals,
};

MP_REGISTER_MODULE(MP_QSTR_obsw_qemu, obsw_qemu_module);

void obsw_qemu_boot(void) {
    // the port's main() allows 10 KiB from its own frame; a Pyboard allows OBSW_STACK_LIMIT
    // (the emulated board's RAM has room: the stack grows down from the top of its 4 MiB)
    mp_cstack_init_with_top(MP_STATE_THREAD(stack_top), OBSW_STACK_LIMIT);
    pyexec_frozen_module("_boot.py", false);
}

// littlefs stamps files with the time; the emulated board has no calendar clock.
uint64_t mp_hal_time_ns(void) {
    return 0;
}
