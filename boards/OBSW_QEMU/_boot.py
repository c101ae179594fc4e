# Frozen into the QEMU board image, run at every (soft) reset: mount the RAM filesystem at "/"
# (formatted on first use), as a Pyboard mounts its internal flash.
import obsw_qemu
import vfs


class _Disk:
    def __init__(self, buf, block=512):
        self.buf = buf
        self.block = block

    def readblocks(self, n, out, offset=0):
        a = n * self.block + offset
        out[:] = self.buf[a : a + len(out)]

    def writeblocks(self, n, data, offset=None):
        a = n * self.block + (offset or 0)
        self.buf[a : a + len(data)] = data

    def ioctl(self, op, arg):
        if op == 4:  # block count
            return len(self.buf) // self.block
        if op == 5:  # block size
            return self.block
        if op == 6:  # erase
            return 0
        return None


_disk = _Disk(obsw_qemu.disk())
try:
    vfs.mount(vfs.VfsLfs2(_disk), "/")
except OSError:
    vfs.VfsLfs2.mkfs(_disk)
    vfs.mount(vfs.VfsLfs2(_disk), "/")
del _disk
