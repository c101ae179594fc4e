"""ST[06] memory areas: RAM, filestore-backed images and mirrored pairs, with their objects.

An area has ``start`` (its first raw address), ``size``, ``writable`` (false for ROM),
``objects`` (object ID -> (name, offset, size): the object memory of ECSS-E-ST-70-41C 6.6,
addressed by object and offset instead of raw address; object 0 is the whole area),
``read(offset, n)``, ``write(offset, data)`` and ``write_atomic(offset, data)`` (all of
``data`` or nothing, even across a power cut). ``copies()`` lists what scrubbing compares:
one copy, or the two of a ``MirroredMemory``.
"""


class BytesMemory:
    """A memory area in RAM (a bytearray) at ``start``."""

    def __init__(self, size, start=0, writable=True, data=None, objects=None):
        self.start = start
        self.size = size
        self.writable = writable
        self.objects = dict(objects) if objects else {}
        self.buf = bytearray(size) if data is None else bytearray(data)

    def read(self, offset, n):
        return bytes(self.buf[offset : offset + n])

    def write(self, offset, data):
        self.buf[offset : offset + len(data)] = data

    def write_atomic(self, offset, data):
        self.write(offset, data)  # one slice assignment: nothing runs in between

    def copies(self):
        return (self,)


class FileMemory:
    """A memory area backed by a file of a filestore (``obsw.cfdp.filestore``), e.g. an
    image; the file is created when missing, filled with ``initial`` (or zeros)."""

    def __init__(self, fs, name, size, start=0, writable=True, objects=None, initial=None):
        self.fs = fs
        self.name = name
        self.start = start
        self.size = size
        self.writable = writable
        self.objects = dict(objects) if objects else {}
        if not fs.exists(name):
            folder = name.rsplit("/", 1)[0] if "/" in name else ""
            if folder and not fs.is_dir(folder):
                fs.mkdir(folder)
            fs.write_bytes(name, bytes(size) if initial is None else bytes(initial))

    def read(self, offset, n):
        return self.fs.read_bytes(self.name, offset, n)

    def write(self, offset, data):
        h = self.fs.open_write(self.name, False)
        try:
            h.write(offset, data)
        finally:
            h.close()

    def write_atomic(self, offset, data):
        """Write a new image beside the old one and rename it over (the filestore's
        ``write_atomic``): a power cut leaves the old image or the new one."""
        image = bytearray(self.fs.read_bytes(self.name))
        image[offset : offset + len(data)] = data
        self.fs.write_atomic(self.name, bytes(image))

    def copies(self):
        return (self,)


class MirroredMemory:
    """Two areas holding the same content (as the safeguard memory's two EEPROMs): reads come
    from the first, every write goes to both; scrubbing repairs one from the other."""

    def __init__(self, first, second):
        if first.size != second.size:
            raise ValueError("mirror of %d octets for %d" % (second.size, first.size))
        self.first = first
        self.second = second
        self.start = first.start
        self.size = first.size
        self.writable = first.writable
        self.objects = first.objects

    def read(self, offset, n):
        return self.first.read(offset, n)

    def write(self, offset, data):
        self.first.write(offset, data)
        self.second.write(offset, data)

    def write_atomic(self, offset, data):
        self.first.write_atomic(offset, data)
        self.second.write_atomic(offset, data)

    def copies(self):
        return (self.first, self.second)


def areas_from_sdb(sdb, filestore=None):
    """The memory areas the spacecraft database declares (file-backed ones need a filestore)."""
    out = {}
    for mid, m in sdb.memories.items():
        objects = m.get("objects")
        if m["file"] and filestore is not None:
            area = FileMemory(filestore, m["file"], m["size"], m["start"], m["writable"], objects)
            if m.get("mirror"):
                image = area.read(0, m["size"])  # a new mirror starts as a copy
                second = FileMemory(
                    filestore, m["mirror"], m["size"], m["start"], m["writable"], None, image
                )
                area = MirroredMemory(area, second)
        else:
            area = BytesMemory(m["size"], m["start"], m["writable"], objects=objects)
        out[mid] = area
    return out
