/* obsw_speedups: the PUS-C TC/TM packet codec hot path in C, for CPython only.
 *
 * The pure-Python codec in micropython/obsw/pus/ stays the definition. These functions take
 * only what they can handle without doubt (exact ints in range, bytes data, one of the
 * layouts PusConfig describes with whole-octet fields) and return None for anything else, so
 * the caller falls back to its Python path, which raises the precise typed error. For any
 * input they do accept, the result is byte for byte what the Python path produces.
 *
 * A layout is one int that obsw.pus.config packs from a PusConfig:
 *   TC: bits 0-2 source ID octets, 3-4 spare octets, 5 PEC, 16.. maximum packet size
 *   TM: bits 0-1 message type counter octets, 2-4 destination ID octets, 5-7 CUC coarse
 *       octets, 8-10 CUC fine octets, 11-12 spare octets, 13 PEC, 16.. maximum packet size
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#include <string.h>

#define API_VERSION 2
#define TC_ID 0x1800u
#define TM_ID 0x0800u

/* slicing-by-8: crc_table[0] is the classic byte table, crc_table[k][n] the register after n
 * followed by k zero octets, so eight octets cost eight lookups and no dependency chain */
static unsigned short crc_table[8][256];

static void
crc_init(void)
{
    for (unsigned n = 0; n < 256; n++) {
        unsigned c = n << 8;
        for (int k = 0; k < 8; k++)
            c = (c & 0x8000u) ? ((c << 1) ^ 0x1021u) : (c << 1);
        crc_table[0][n] = (unsigned short)(c & 0xFFFFu);
    }
    for (int k = 1; k < 8; k++)
        for (unsigned n = 0; n < 256; n++) {
            unsigned c = crc_table[k - 1][n];
            crc_table[k][n] = (unsigned short)(((c << 8) & 0xFFFFu) ^ crc_table[0][c >> 8]);
        }
}

/* CRC-16/CCITT-FALSE (poly 0x1021, not reflected, no final XOR) continuing from reg */
static unsigned
crc16(unsigned reg, const unsigned char *p, Py_ssize_t n)
{
    while (n >= 8) {
        unsigned a = ((reg >> 8) ^ p[0]) & 0xFFu, b = (reg ^ p[1]) & 0xFFu;
        reg = crc_table[7][a] ^ crc_table[6][b] ^ crc_table[5][p[2]] ^ crc_table[4][p[3]] ^
              crc_table[3][p[4]] ^ crc_table[2][p[5]] ^ crc_table[1][p[6]] ^ crc_table[0][p[7]];
        p += 8;
        n -= 8;
    }
    while (n-- > 0)
        reg = ((reg << 8) & 0xFFFFu) ^ crc_table[0][((reg >> 8) ^ *p++) & 0xFFu];
    return reg;
}

/* 0 with *out set if v is an exact int in [0, max]; -1 otherwise, with no error left set */
static int
field(PyObject *v, unsigned long long max, unsigned long long *out)
{
    int overflow;
    long long x;

    if (!PyLong_CheckExact(v))
        return -1;
    x = PyLong_AsLongLongAndOverflow(v, &overflow);
    if (x == -1 && PyErr_Occurred()) {
        PyErr_Clear();
        return -1;
    }
    if (overflow || x < 0 || (unsigned long long)x > max)
        return -1;
    *out = (unsigned long long)x;
    return 0;
}

static unsigned long long
max_for(int octets)
{
    return octets >= 8 ? ~0ULL : (1ULL << (8 * octets)) - 1;
}

static unsigned char *
put(unsigned char *p, unsigned long long v, int octets)
{
    for (int i = octets - 1; i >= 0; i--) {
        p[i] = (unsigned char)(v & 0xFF);
        v >>= 8;
    }
    return p + octets;
}

static unsigned long long
get(const unsigned char *p, int octets)
{
    unsigned long long v = 0;
    for (int i = 0; i < octets; i++)
        v = (v << 8) | p[i];
    return v;
}

/* the layout int: -1 if it is not an exact int (no error left set) */
static long long
layout_of(PyObject *v)
{
    unsigned long long x;
    if (field(v, 0x7FFFFFFFFFFFULL, &x))
        return -1;
    return (long long)x;
}

/* Borrow a contiguous octet buffer from bytes, bytearray or a one-dimensional memoryview of
 * octets; 0 on success (release with PyBuffer_Release), -1 to take the Python path. */
static int
octets_of(PyObject *buf, Py_buffer *view)
{
    if (PyMemoryView_Check(buf)) {
        Py_buffer *m = PyMemoryView_GET_BUFFER(buf);
        if (m->ndim != 1 || m->itemsize != 1 || !PyBuffer_IsContiguous(m, 'C'))
            return -1;
    }
    else if (!PyBytes_CheckExact(buf) && !PyByteArray_CheckExact(buf)) {
        return -1;
    }
    if (PyObject_GetBuffer(buf, view, PyBUF_SIMPLE) < 0) {
        PyErr_Clear();
        return -1;
    }
    return 0;
}

/* header words and the PUS version octet shared by TC and TM */
static unsigned char *
put_common(unsigned char *p, unsigned id, unsigned long long apid, unsigned long long flags,
           unsigned long long count, Py_ssize_t total, unsigned long long low,
           unsigned long long service, unsigned long long subtype)
{
    p = put(p, id | apid, 2);
    p = put(p, (flags << 14) | count, 2);
    p = put(p, (unsigned long long)(total - 7), 2);
    *p++ = (unsigned char)(0x20 | low);
    *p++ = (unsigned char)service;
    *p++ = (unsigned char)subtype;
    return p;
}

static PyObject *
finish(PyObject *out, unsigned char *p, PyObject *data, int spare, int pec)
{
    unsigned char *start = (unsigned char *)PyBytes_AS_STRING(out);
    Py_ssize_t n = PyBytes_GET_SIZE(data);

    if (spare) {
        memset(p, 0, (size_t)spare);
        p += spare;
    }
    if (n) {
        memcpy(p, PyBytes_AS_STRING(data), (size_t)n);
        p += n;
    }
    if (pec) {
        unsigned c = crc16(0xFFFFu, start, p - start);
        p[0] = (unsigned char)(c >> 8);
        p[1] = (unsigned char)(c & 0xFF);
    }
    return out;
}

/* tc_pack(apid, seq_count, seq_flags, ack, service, subtype, source_id, data, layout)
 * -> the whole TC as bytes, or None to take the Python path */
static PyObject *
tc_pack_values(PyObject *const *args)
{
    unsigned long long apid, count, flags, ack, service, subtype, source;
    long long layout;
    int sid, spare, pec;
    Py_ssize_t total;
    PyObject *data, *out;
    unsigned char *p;

    layout = layout_of(args[8]);
    if (layout < 0)
        Py_RETURN_NONE;
    sid = (int)(layout & 7);
    spare = (int)((layout >> 3) & 3);
    pec = (int)((layout >> 5) & 1);
    data = args[7];
    if (sid < 1 || sid > 4 || !PyBytes_CheckExact(data) || field(args[0], 0x7FF, &apid) ||
        field(args[1], 0x3FFF, &count) || field(args[2], 3, &flags) ||
        field(args[3], 15, &ack) || field(args[4], 255, &service) ||
        field(args[5], 255, &subtype) || field(args[6], max_for(sid), &source))
        Py_RETURN_NONE;
    total = 9 + sid + spare + 2 * pec + PyBytes_GET_SIZE(data);
    if (total - 7 > 0xFFFF || total > (layout >> 16))
        Py_RETURN_NONE;
    out = PyBytes_FromStringAndSize(NULL, total);
    if (out == NULL)
        return NULL;
    p = (unsigned char *)PyBytes_AS_STRING(out);
    p = put_common(p, TC_ID, apid, flags, count, total, ack, service, subtype);
    p = put(p, source, sid);
    return finish(out, p, data, spare, pec);
}

static PyObject *
tc_pack(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "tc_pack takes 9 arguments");
        return NULL;
    }
    return tc_pack_values(args);
}

/* tm_pack(apid, seq_count, seq_flags, time_ref, service, subtype, message_counter,
 *         destination_id, time, data, layout) -> the whole TM as bytes, or None */
static PyObject *
tm_pack_values(PyObject *const *args)
{
    unsigned long long apid, count, flags, ref, service, subtype, counter, dest;
    unsigned long long coarse = 0, fine = 0;
    long long layout;
    int cnt, dst, tc, tf, spare, pec;
    Py_ssize_t total;
    PyObject *data, *t, *out;
    unsigned char *p;

    layout = layout_of(args[10]);
    if (layout < 0)
        Py_RETURN_NONE;
    cnt = (int)(layout & 3);
    dst = (int)((layout >> 2) & 7);
    tc = (int)((layout >> 5) & 7);
    tf = (int)((layout >> 8) & 7);
    spare = (int)((layout >> 11) & 3);
    pec = (int)((layout >> 13) & 1);
    data = args[9];
    t = args[8];
    if (cnt < 1 || dst < 1 || dst > 4 || tc < 1 || tc > 4 || tf < 1 || tf > 4 ||
        !PyBytes_CheckExact(data) || field(args[0], 0x7FF, &apid) ||
        field(args[1], 0x3FFF, &count) || field(args[2], 3, &flags) ||
        field(args[3], 15, &ref) || field(args[4], 255, &service) ||
        field(args[5], 255, &subtype) || field(args[6], max_for(cnt), &counter) ||
        field(args[7], max_for(dst), &dest))
        Py_RETURN_NONE;
    if (t != Py_None) {
        if (!PyTuple_CheckExact(t) || PyTuple_GET_SIZE(t) != 2 ||
            field(PyTuple_GET_ITEM(t, 0), max_for(tc), &coarse) ||
            field(PyTuple_GET_ITEM(t, 1), max_for(tf), &fine))
            Py_RETURN_NONE;
    }
    total = 9 + cnt + dst + tc + tf + spare + 2 * pec + PyBytes_GET_SIZE(data);
    if (total - 7 > 0xFFFF || total > (layout >> 16))
        Py_RETURN_NONE;
    out = PyBytes_FromStringAndSize(NULL, total);
    if (out == NULL)
        return NULL;
    p = (unsigned char *)PyBytes_AS_STRING(out);
    p = put_common(p, TM_ID, apid, flags, count, total, ref, service, subtype);
    p = put(p, counter, cnt);
    p = put(p, dest, dst);
    p = put(p, coarse, tc);
    p = put(p, fine, tf);
    return finish(out, p, data, spare, pec);
}

static PyObject *
tm_pack(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 11) {
        PyErr_SetString(PyExc_TypeError, "tm_pack takes 11 arguments");
        return NULL;
    }
    return tm_pack_values(args);
}

static PyObject *s_apid, *s_service, *s_subtype, *s_data, *s_seq_count, *s_ack, *s_source_id,
    *s_seq_flags, *s_config, *s_message_counter, *s_destination_id, *s_time, *s_time_ref,
    *empty_tuple;

/* set name = value on obj, taking the reference to value; -1 on error */
static int
set_new(PyObject *obj, PyObject *name, PyObject *value)
{
    int rc;
    if (value == NULL)
        return -1;
    rc = PyObject_SetAttr(obj, name, value);
    Py_DECREF(value);
    return rc;
}

/* a packet of type cls made like object.__new__(cls), or NULL */
static PyObject *
blank(PyObject *cls)
{
    return PyBaseObject_Type.tp_new((PyTypeObject *)cls, empty_tuple, NULL);
}

/* check the frame of a whole packet: type ID, length, version octet, size, PEC; 0 if good */
static int
frame_ok(const unsigned char *b, Py_ssize_t n, Py_ssize_t min, unsigned id, long long layout,
         int pec)
{
    if (n < min || n > (layout >> 16))
        return -1;
    if (((b[0] << 8 | b[1]) & 0xF800u) != id || (Py_ssize_t)get(b + 4, 2) + 7 != n ||
        (b[6] & 0xF0) != 0x20)
        return -1;
    if (pec && crc16(0xFFFFu, b, n) != 0)
        return -1;
    return 0;
}

/* Direct slot access. PusTc and PusTm keep their fields in __slots__; reading and writing
 * them at their offsets skips the attribute protocol. A class qualifies only if every field
 * name resolves to a plain writable object slot (a subclass that turns one into a property
 * does not); the offsets are cached per class and type version, so changing the class
 * invalidates them. */
#define TC_FIELDS 9 /* apid seq_count seq_flags ack service subtype source_id data config */
#define TM_FIELDS 11 /* apid seq_count seq_flags time_ref service subtype message_counter
                        destination_id time data config */
#define MAX_FIELDS 11

typedef struct {
    PyTypeObject *type;
    unsigned int tag;
    Py_ssize_t offset[MAX_FIELDS];
} slot_cache;

static PyObject **tc_names[TC_FIELDS] = {&s_apid,    &s_seq_count, &s_seq_flags,
                                         &s_ack,     &s_service,   &s_subtype,
                                         &s_source_id, &s_data,    &s_config};
static PyObject **tm_names[TM_FIELDS] = {
    &s_apid,    &s_seq_count,       &s_seq_flags,      &s_time_ref, &s_service, &s_subtype,
    &s_message_counter, &s_destination_id, &s_time, &s_data,     &s_config};
static slot_cache tc_slots, tm_slots;

/* the slot offsets of type t for names, or NULL if t does not qualify (no error left set) */
static const Py_ssize_t *
slots_of(PyTypeObject *t, PyObject **names[], int count, slot_cache *cache)
{
    Py_ssize_t offset[MAX_FIELDS];

    if (cache->type == t && cache->tag != 0 && cache->tag == t->tp_version_tag &&
        PyType_HasFeature(t, Py_TPFLAGS_VALID_VERSION_TAG))
        return cache->offset;
    for (int i = 0; i < count; i++) {
        PyObject *d = _PyType_Lookup(t, *names[i]); /* borrowed */
        PyMemberDef *m;
        if (d == NULL || Py_TYPE(d) != &PyMemberDescr_Type)
            return NULL;
        m = ((PyMemberDescrObject *)d)->d_member;
        if (m->type != T_OBJECT_EX || (m->flags & READONLY))
            return NULL;
        offset[i] = m->offset;
    }
    if (!PyType_HasFeature(t, Py_TPFLAGS_VALID_VERSION_TAG) || t->tp_version_tag == 0)
        return NULL; /* nothing to key a cache on: take the attribute path */
    cache->type = t;
    cache->tag = t->tp_version_tag;
    memcpy(cache->offset, offset, sizeof(offset));
    return cache->offset;
}

#define SLOT(obj, off) (*(PyObject **)((char *)(obj) + (off)))

/* gather the values of the first count slots; -1 if one is unset or the class does not
 * qualify */
static int
gather(PyObject *obj, PyObject **names[], int count, slot_cache *cache, PyObject **out)
{
    const Py_ssize_t *off = slots_of(Py_TYPE(obj), names, count + 1, cache);
    if (off == NULL)
        return -1;
    for (int i = 0; i < count; i++)
        if ((out[i] = SLOT(obj, off[i])) == NULL)
            return -1;
    return 0;
}

/* tc_pack_slots(tc, layout) -> tc.pack() for a whole-octet layout, or None */
static PyObject *
tc_pack_slots(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    PyObject *v[9];
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "tc_pack_slots takes 2 arguments");
        return NULL;
    }
    if (gather(args[0], tc_names, 8, &tc_slots, v))
        Py_RETURN_NONE;
    v[8] = args[1];
    return tc_pack_values(v);
}

/* tm_pack_slots(tm, layout) -> tm.pack() for a whole-octet layout, or None */
static PyObject *
tm_pack_slots(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    PyObject *v[11];
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "tm_pack_slots takes 2 arguments");
        return NULL;
    }
    if (gather(args[0], tm_names, 10, &tm_slots, v))
        Py_RETURN_NONE;
    v[10] = args[1];
    return tm_pack_values(v);
}

/* fill the slots of a blank object with new references from values (stolen, all non-NULL);
 * on a NULL value releases the rest and returns -1 */
static int
fill(PyObject *obj, const Py_ssize_t *off, PyObject **values, int count)
{
    int bad = 0;
    for (int i = 0; i < count; i++)
        if (values[i] == NULL)
            bad = 1;
    if (bad) {
        for (int i = 0; i < count; i++)
            Py_XDECREF(values[i]);
        return -1;
    }
    for (int i = 0; i < count; i++)
        SLOT(obj, off[i]) = values[i];
    return 0;
}

/* tc_unpack(cls, buf, layout, config) -> a cls instance for a well-formed TC, or None */
static PyObject *
tc_unpack(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Py_buffer view;
    const unsigned char *b;
    long long layout;
    int sid, spare, pec;
    Py_ssize_t n, off;
    unsigned pid, psc;
    PyObject *obj = NULL, *cls;
    const Py_ssize_t *slot;

    (void)self;
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "tc_unpack takes 4 arguments");
        return NULL;
    }
    cls = args[0];
    layout = layout_of(args[2]);
    if (layout < 0 || !PyType_Check(cls))
        Py_RETURN_NONE;
    sid = (int)(layout & 7);
    spare = (int)((layout >> 3) & 3);
    pec = (int)((layout >> 5) & 1);
    if (sid < 1 || sid > 4 || octets_of(args[1], &view))
        Py_RETURN_NONE;
    b = (const unsigned char *)view.buf;
    n = view.len;
    off = 9 + sid + spare;
    if (frame_ok(b, n, off + 2 * pec, TC_ID, layout, pec)) {
        PyBuffer_Release(&view);
        Py_RETURN_NONE;
    }
    pid = (unsigned)get(b, 2);
    psc = (unsigned)get(b + 2, 2);
    obj = blank(cls);
    slot = obj == NULL ? NULL : slots_of(Py_TYPE(obj), tc_names, TC_FIELDS, &tc_slots);
    if (slot != NULL) {
        PyObject *v[TC_FIELDS] = {
            PyLong_FromLong(pid & 0x7FF),
            PyLong_FromLong(psc & 0x3FFF),
            PyLong_FromLong(psc >> 14),
            PyLong_FromLong(b[6] & 15),
            PyLong_FromLong(b[7]),
            PyLong_FromLong(b[8]),
            PyLong_FromUnsignedLongLong(get(b + 9, sid)),
            PyBytes_FromStringAndSize((const char *)b + off, n - off - 2 * pec),
            Py_NewRef(args[3]),
        };
        if (fill(obj, slot, v, TC_FIELDS))
            Py_CLEAR(obj);
    }
    else if (obj == NULL || set_new(obj, s_apid, PyLong_FromLong(pid & 0x7FF)) ||
        set_new(obj, s_service, PyLong_FromLong(b[7])) ||
        set_new(obj, s_subtype, PyLong_FromLong(b[8])) ||
        set_new(obj, s_data,
                PyBytes_FromStringAndSize((const char *)b + off, n - off - 2 * pec)) ||
        set_new(obj, s_seq_count, PyLong_FromLong(psc & 0x3FFF)) ||
        set_new(obj, s_ack, PyLong_FromLong(b[6] & 15)) ||
        set_new(obj, s_source_id, PyLong_FromUnsignedLongLong(get(b + 9, sid))) ||
        set_new(obj, s_seq_flags, PyLong_FromLong(psc >> 14)) ||
        PyObject_SetAttr(obj, s_config, args[3])) {
        Py_CLEAR(obj);
    }
    PyBuffer_Release(&view);
    return obj;
}

/* tm_unpack(cls, buf, layout, config) -> a cls instance for a well-formed TM, or None */
static PyObject *
tm_unpack(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Py_buffer view;
    const unsigned char *b;
    long long layout;
    int cnt, dst, tc, tf, spare, pec;
    Py_ssize_t n, off;
    unsigned pid, psc;
    const unsigned char *q;
    PyObject *obj = NULL, *cls, *t;
    const Py_ssize_t *slot;

    (void)self;
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "tm_unpack takes 4 arguments");
        return NULL;
    }
    cls = args[0];
    layout = layout_of(args[2]);
    if (layout < 0 || !PyType_Check(cls))
        Py_RETURN_NONE;
    cnt = (int)(layout & 3);
    dst = (int)((layout >> 2) & 7);
    tc = (int)((layout >> 5) & 7);
    tf = (int)((layout >> 8) & 7);
    spare = (int)((layout >> 11) & 3);
    pec = (int)((layout >> 13) & 1);
    if (cnt < 1 || dst < 1 || dst > 4 || tc < 1 || tc > 4 || tf < 1 || tf > 4 ||
        octets_of(args[1], &view))
        Py_RETURN_NONE;
    b = (const unsigned char *)view.buf;
    n = view.len;
    off = 9 + cnt + dst + tc + tf + spare;
    if (frame_ok(b, n, off + 2 * pec, TM_ID, layout, pec)) {
        PyBuffer_Release(&view);
        Py_RETURN_NONE;
    }
    pid = (unsigned)get(b, 2);
    psc = (unsigned)get(b + 2, 2);
    q = b + 9 + cnt + dst;
    t = Py_BuildValue("(KK)", get(q, tc), get(q + tc, tf));
    obj = blank(cls);
    slot = obj == NULL ? NULL : slots_of(Py_TYPE(obj), tm_names, TM_FIELDS, &tm_slots);
    if (t != NULL && slot != NULL) {
        PyObject *v[TM_FIELDS] = {
            PyLong_FromLong(pid & 0x7FF),
            PyLong_FromLong(psc & 0x3FFF),
            PyLong_FromLong(psc >> 14),
            PyLong_FromLong(b[6] & 15),
            PyLong_FromLong(b[7]),
            PyLong_FromLong(b[8]),
            PyLong_FromUnsignedLongLong(get(b + 9, cnt)),
            PyLong_FromUnsignedLongLong(get(b + 9 + cnt, dst)),
            Py_NewRef(t),
            PyBytes_FromStringAndSize((const char *)b + off, n - off - 2 * pec),
            Py_NewRef(args[3]),
        };
        if (fill(obj, slot, v, TM_FIELDS))
            Py_CLEAR(obj);
    }
    else if (t == NULL || obj == NULL || set_new(obj, s_apid, PyLong_FromLong(pid & 0x7FF)) ||
        set_new(obj, s_service, PyLong_FromLong(b[7])) ||
        set_new(obj, s_subtype, PyLong_FromLong(b[8])) ||
        set_new(obj, s_data,
                PyBytes_FromStringAndSize((const char *)b + off, n - off - 2 * pec)) ||
        set_new(obj, s_seq_count, PyLong_FromLong(psc & 0x3FFF)) ||
        set_new(obj, s_message_counter, PyLong_FromUnsignedLongLong(get(b + 9, cnt))) ||
        set_new(obj, s_destination_id, PyLong_FromUnsignedLongLong(get(b + 9 + cnt, dst))) ||
        PyObject_SetAttr(obj, s_time, t) ||
        set_new(obj, s_time_ref, PyLong_FromLong(b[6] & 15)) ||
        set_new(obj, s_seq_flags, PyLong_FromLong(psc >> 14)) ||
        PyObject_SetAttr(obj, s_config, args[3])) {
        Py_CLEAR(obj);
    }
    Py_XDECREF(t);
    PyBuffer_Release(&view);
    return obj;
}

/* crc16_ccitt(data, register) -> CRC-16/CCITT-FALSE of data continuing from register */
static PyObject *
crc16_ccitt(PyObject *self, PyObject *args)
{
    Py_buffer view;
    unsigned int reg;
    unsigned c;

    (void)self;
    if (!PyArg_ParseTuple(args, "y*I:crc16_ccitt", &view, &reg))
        return NULL;
    c = crc16(reg & 0xFFFFu, (const unsigned char *)view.buf, view.len);
    PyBuffer_Release(&view);
    return PyLong_FromUnsignedLong(c);
}


/* ------------------------------------------------------------------------------------------
 * CBOR for the interaction layer's wire: the deterministic encoding of obsw.cbor (and
 * cbor2.dumps(canonical=True)) for exact int, bool, None, float, str, bytes, bytearray, list,
 * tuple and dict, and a decoder for the same subset with definite lengths. Anything else
 * (tags, bignums, memoryviews, subclasses, simple values, indefinite lengths, malformed or
 * too deep input) is declined, and the caller takes the Python path, which decides and raises.
 */
#define CBOR_MAX_DEPTH 16 /* deeper values go the Python way, which knows the limits */

typedef struct {
    unsigned char *buf;
    Py_ssize_t len, cap;
} cbuf;

static int
cb_reserve(cbuf *b, Py_ssize_t more)
{
    if (b->len + more <= b->cap)
        return 0;
    Py_ssize_t cap = b->cap ? b->cap : 64;
    while (cap < b->len + more)
        cap *= 2;
    unsigned char *n = PyMem_Realloc(b->buf, (size_t)cap);
    if (n == NULL)
        return -1;
    b->buf = n;
    b->cap = cap;
    return 0;
}

static int
cb_put(cbuf *b, const void *p, Py_ssize_t n)
{
    if (cb_reserve(b, n))
        return -1;
    memcpy(b->buf + b->len, p, (size_t)n);
    b->len += n;
    return 0;
}

static int
cb_head(cbuf *b, unsigned major, unsigned long long n)
{
    unsigned char h[9];
    int k;
    if (n < 24) {
        h[0] = (unsigned char)(major | n);
        k = 1;
    }
    else if (n < 0x100) {
        h[0] = (unsigned char)(major | 24);
        k = 2;
    }
    else if (n < 0x10000) {
        h[0] = (unsigned char)(major | 25);
        k = 3;
    }
    else if (n < 0x100000000ULL) {
        h[0] = (unsigned char)(major | 26);
        k = 5;
    }
    else {
        h[0] = (unsigned char)(major | 27);
        k = 9;
    }
    put(h + 1, n, k - 1);
    return cb_put(b, h, k);
}

/* 1 encoded, 0 declined, -1 error (set) */
static int cb_encode(cbuf *b, PyObject *v, int depth);

static int
cb_float(cbuf *b, double x)
{
    unsigned char h[9];
    if (x != x)
        return cb_put(b, "\xf9\x7e\x00", 3);
    if (PyFloat_Pack2(x, (char *)h + 1, 0) == 0) {
        if (PyFloat_Unpack2((const char *)h + 1, 0) == x) {
            h[0] = 0xF9;
            return cb_put(b, h, 3);
        }
    }
    else
        PyErr_Clear();
    if (PyFloat_Pack4(x, (char *)h + 1, 0) == 0) {
        if (PyFloat_Unpack4((const char *)h + 1, 0) == x) {
            h[0] = 0xFA;
            return cb_put(b, h, 5);
        }
    }
    else
        PyErr_Clear();
    h[0] = 0xFB;
    if (PyFloat_Pack8(x, (char *)h + 1, 0))
        return -1;
    return cb_put(b, h, 9);
}

typedef struct {
    Py_ssize_t off, len; /* the encoded key within the key buffer */
    PyObject *value;
} cb_pair;

static const unsigned char *cb_sort_base;

static int
cb_pair_cmp(const void *x, const void *y)
{
    const cb_pair *a = x, *c = y;
    if (a->len != c->len)
        return a->len < c->len ? -1 : 1;
    return memcmp(cb_sort_base + a->off, cb_sort_base + c->off, (size_t)a->len);
}

static int
cb_dict(cbuf *b, PyObject *d, int depth)
{
    Py_ssize_t n = PyDict_GET_SIZE(d), pos = 0, i = 0;
    PyObject *k, *v;
    cbuf keys = {NULL, 0, 0};
    cb_pair *pairs;
    int rc = 1;

    if (cb_head(b, 0xA0, (unsigned long long)n))
        return -1;
    if (n == 0)
        return 1;
    pairs = PyMem_Malloc(sizeof(cb_pair) * (size_t)n);
    if (pairs == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    while (PyDict_Next(d, &pos, &k, &v)) {
        Py_ssize_t start = keys.len;
        if (i >= n) { /* changed size while encoding: let Python decide */
            rc = 0;
            break;
        }
        rc = cb_encode(&keys, k, depth - 1);
        if (rc != 1)
            break;
        pairs[i].off = start;
        pairs[i].len = keys.len - start;
        pairs[i].value = v;
        i++;
    }
    if (rc == 1 && i != n)
        rc = 0;
    if (rc == 1) {
        cb_sort_base = keys.buf; /* callers hold the GIL: one sort at a time */
        qsort(pairs, (size_t)n, sizeof(cb_pair), cb_pair_cmp);
        for (i = 0; i < n && rc == 1; i++) {
            if (cb_put(b, keys.buf + pairs[i].off, pairs[i].len))
                rc = -1;
            else
                rc = cb_encode(b, pairs[i].value, depth - 1);
        }
    }
    PyMem_Free(pairs);
    PyMem_Free(keys.buf);
    return rc;
}

static int
cb_encode(cbuf *b, PyObject *v, int depth)
{
    PyTypeObject *t = Py_TYPE(v);
    if (t == &PyLong_Type) {
        int overflow;
        long long x = PyLong_AsLongLongAndOverflow(v, &overflow);
        if (overflow == 0) {
            if (x == -1 && PyErr_Occurred())
                return -1;
            if (x >= 0)
                return cb_head(b, 0x00, (unsigned long long)x) ? -1 : 1;
            return cb_head(b, 0x20, (unsigned long long)(-1 - x)) ? -1 : 1;
        }
        if (overflow > 0) {
            unsigned long long u = PyLong_AsUnsignedLongLong(v);
            if (u == (unsigned long long)-1 && PyErr_Occurred()) {
                PyErr_Clear();
                return 0; /* a bignum */
            }
            return cb_head(b, 0x00, u) ? -1 : 1;
        }
        return 0; /* below -2**63: bignum or not, Python decides */
    }
    if (t == &PyUnicode_Type) {
        Py_ssize_t n;
        const char *s = PyUnicode_AsUTF8AndSize(v, &n);
        if (s == NULL) {
            PyErr_Clear();
            return 0;
        }
        return (cb_head(b, 0x60, (unsigned long long)n) || cb_put(b, s, n)) ? -1 : 1;
    }
    if (t == &PyBytes_Type) {
        Py_ssize_t n = PyBytes_GET_SIZE(v);
        return (cb_head(b, 0x40, (unsigned long long)n) || cb_put(b, PyBytes_AS_STRING(v), n))
                   ? -1
                   : 1;
    }
    if (t == &PyByteArray_Type) {
        Py_ssize_t n = PyByteArray_GET_SIZE(v);
        return (cb_head(b, 0x40, (unsigned long long)n) ||
                cb_put(b, PyByteArray_AS_STRING(v), n))
                   ? -1
                   : 1;
    }
    if (t == &PyList_Type || t == &PyTuple_Type) {
        Py_ssize_t n = t == &PyList_Type ? PyList_GET_SIZE(v) : PyTuple_GET_SIZE(v);
        if (depth <= 0)
            return 0;
        if (cb_head(b, 0x80, (unsigned long long)n))
            return -1;
        for (Py_ssize_t i = 0; i < n; i++) {
            PyObject *x;
            int rc;
            if (t == &PyList_Type) {
                if (i >= PyList_GET_SIZE(v))
                    return 0; /* shrank while encoding */
                x = PyList_GET_ITEM(v, i);
            }
            else
                x = PyTuple_GET_ITEM(v, i);
            Py_INCREF(x);
            rc = cb_encode(b, x, depth - 1);
            Py_DECREF(x);
            if (rc != 1)
                return rc;
        }
        if (t == &PyList_Type && PyList_GET_SIZE(v) != n)
            return 0;
        return 1;
    }
    if (t == &PyDict_Type)
        return depth <= 0 ? 0 : cb_dict(b, v, depth);
    if (v == Py_True || v == Py_False)
        return cb_put(b, v == Py_True ? "\xf5" : "\xf4", 1) ? -1 : 1;
    if (v == Py_None)
        return cb_put(b, "\xf6", 1) ? -1 : 1;
    if (t == &PyFloat_Type)
        return cb_float(b, PyFloat_AS_DOUBLE(v)) ? -1 : 1;
    return 0;
}

/* cbor_frame(value) -> 4-byte big-endian length + deterministic CBOR of value, or None */
static PyObject *
cbor_frame(PyObject *self, PyObject *v)
{
    cbuf b = {NULL, 0, 0};
    PyObject *out = NULL;
    int rc;
    (void)self;
    if (cb_reserve(&b, 64)) {
        PyErr_NoMemory();
        return NULL;
    }
    b.len = 4;
    rc = cb_encode(&b, v, CBOR_MAX_DEPTH);
    if (rc == 1 && b.len - 4 <= 0xFFFFFFFFLL) {
        put(b.buf, (unsigned long long)(b.len - 4), 4);
        out = PyBytes_FromStringAndSize((const char *)b.buf, b.len);
    }
    else if (rc >= 0) {
        out = Py_NewRef(Py_None);
    }
    PyMem_Free(b.buf);
    return out;
}

/* the decoder: 1 with *out set, 0 declined, -1 error (set) */
static int
cd_item(const unsigned char *p, Py_ssize_t n, Py_ssize_t *pos, int depth, PyObject **out)
{
    unsigned ib, major, ai;
    unsigned long long arg;
    Py_ssize_t i = *pos;

    if (i >= n)
        return 0;
    ib = p[i++];
    major = ib & 0xE0;
    ai = ib & 0x1F;
    if (ai < 24)
        arg = ai;
    else if (ai < 28) {
        int k = 1 << (ai - 24);
        if (n - i < k)
            return 0;
        arg = get(p + i, k);
        i += k;
    }
    else
        return 0; /* indefinite lengths and reserved values: Python */
    switch (major) {
    case 0x00:
        *out = PyLong_FromUnsignedLongLong(arg);
        break;
    case 0x20:
        if (arg > (unsigned long long)LLONG_MAX)
            return 0;
        *out = PyLong_FromLongLong(-1 - (long long)arg);
        break;
    case 0x40:
    case 0x60:
        if (arg > (unsigned long long)(n - i))
            return 0;
        if (major == 0x40)
            *out = PyBytes_FromStringAndSize((const char *)p + i, (Py_ssize_t)arg);
        else {
            *out = PyUnicode_DecodeUTF8((const char *)p + i, (Py_ssize_t)arg, NULL);
            if (*out == NULL) {
                PyErr_Clear();
                return 0;
            }
        }
        i += (Py_ssize_t)arg;
        break;
    case 0x80: {
        PyObject *list;
        if (depth <= 0 || arg > (unsigned long long)(n - i))
            return 0;
        list = PyList_New((Py_ssize_t)arg);
        if (list == NULL)
            return -1;
        for (Py_ssize_t k = 0; k < (Py_ssize_t)arg; k++) {
            PyObject *x;
            int rc = cd_item(p, n, &i, depth - 1, &x);
            if (rc != 1) {
                Py_DECREF(list);
                return rc;
            }
            PyList_SET_ITEM(list, k, x);
        }
        *out = list;
        break;
    }
    case 0xA0: {
        PyObject *d;
        if (depth <= 0 || arg > (unsigned long long)(n - i) / 2)
            return 0;
        d = PyDict_New();
        if (d == NULL)
            return -1;
        for (unsigned long long k = 0; k < arg; k++) {
            PyObject *key, *val;
            int rc;
            if (i < n && ((p[i] & 0xE0) == 0x80 || (p[i] & 0xE0) == 0xA0)) {
                Py_DECREF(d); /* array or map keys become tuples in Python: let it */
                return 0;
            }
            rc = cd_item(p, n, &i, depth - 1, &key);
            if (rc != 1) {
                Py_DECREF(d);
                return rc;
            }
            rc = cd_item(p, n, &i, depth - 1, &val);
            if (rc != 1) {
                Py_DECREF(key);
                Py_DECREF(d);
                return rc;
            }
            rc = PyDict_SetItem(d, key, val);
            Py_DECREF(key);
            Py_DECREF(val);
            if (rc) {
                Py_DECREF(d);
                return -1;
            }
        }
        *out = d;
        break;
    }
    case 0xE0:
        if (ai == 20)
            *out = Py_NewRef(Py_False);
        else if (ai == 21)
            *out = Py_NewRef(Py_True);
        else if (ai == 22)
            *out = Py_NewRef(Py_None);
        else if (ai == 25 || ai == 26 || ai == 27) {
            double x = ai == 25   ? PyFloat_Unpack2((const char *)p + i - 2, 0)
                       : ai == 26 ? PyFloat_Unpack4((const char *)p + i - 4, 0)
                                  : PyFloat_Unpack8((const char *)p + i - 8, 0);
            if (x == -1.0 && PyErr_Occurred())
                return -1;
            *out = PyFloat_FromDouble(x);
        }
        else
            return 0; /* undefined and the other simple values: Python */
        break;
    default:
        return 0; /* tags */
    }
    if (*out == NULL)
        return -1;
    *pos = i;
    return 1;
}

/* cbor_loads(data, declined) -> the value of the one CBOR item data holds, or declined */
static PyObject *
cbor_loads(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Py_buffer view;
    Py_ssize_t pos = 0;
    PyObject *v = NULL;
    int rc;
    (void)self;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "cbor_loads takes 2 arguments");
        return NULL;
    }
    if (octets_of(args[0], &view))
        return Py_NewRef(args[1]);
    rc = cd_item((const unsigned char *)view.buf, view.len, &pos, CBOR_MAX_DEPTH, &v);
    PyBuffer_Release(&view);
    if (rc < 0)
        return NULL;
    if (rc == 0 || pos != view.len) {
        Py_XDECREF(v);
        return Py_NewRef(args[1]);
    }
    return v;
}

/* cbor_frame_loads(data, declined, max_frame) -> the value of the one length-prefixed frame
 * data holds exactly (4-byte big-endian length, then one CBOR item), or declined: for anything
 * else (several frames, a part of one, a length above max_frame, a value cbor_loads declines)
 * the Python reader takes over and decides. */
static PyObject *
cbor_frame_loads(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Py_buffer view;
    Py_ssize_t pos = 4;
    PyObject *v = NULL;
    const unsigned char *p;
    unsigned long long length;
    long long limit;
    int rc;
    (void)self;
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "cbor_frame_loads takes 3 arguments");
        return NULL;
    }
    limit = PyLong_AsLongLong(args[2]);
    if (limit == -1 && PyErr_Occurred())
        return NULL;
    if (octets_of(args[0], &view))
        return Py_NewRef(args[1]);
    p = (const unsigned char *)view.buf;
    if (view.len < 5) {
        PyBuffer_Release(&view);
        return Py_NewRef(args[1]);
    }
    length = ((unsigned long long)p[0] << 24) | ((unsigned long long)p[1] << 16) |
             ((unsigned long long)p[2] << 8) | (unsigned long long)p[3];
    if (length + 4 != (unsigned long long)view.len || (long long)length > limit) {
        PyBuffer_Release(&view);
        return Py_NewRef(args[1]);
    }
    rc = cd_item(p, view.len, &pos, CBOR_MAX_DEPTH, &v);
    PyBuffer_Release(&view);
    if (rc < 0)
        return NULL;
    if (rc == 0 || pos != view.len) {
        Py_XDECREF(v);
        return Py_NewRef(args[1]);
    }
    return v;
}

/* ------------------------------------------------------------------------------------------
 * Viterbi decoding of the CCSDS rate 1/2, K=7 code (131.0-B 3.3): the add-compare-select and
 * the chainback of obsw.frames.viterbi.Viterbi27 on signed 8-bit soft symbols (positive: 1).
 * Same metrics, same tie rule (the lower predecessor wins), so the same bits as the Python loop.
 * Decisions are one little-endian 64-bit word per bit: bit s set when state s came from s/2+32.
 */
static int
v27_parity(unsigned x)
{
    x ^= x >> 4;
    x ^= x >> 2;
    x ^= x >> 1;
    return (int)(x & 1u);
}

static PyObject *
viterbi27(PyObject *self, PyObject *args)
{
    PyObject *metrics, *decisions, *out;
    Py_buffer view;
    Py_ssize_t n, base;
    long long p[64], q[64];
    int tab[32];
    const signed char *sy;
    unsigned char *dst;

    (void)self;
    if (!PyArg_ParseTuple(args, "O!y*nO!:viterbi27", &PyList_Type, &metrics, &view, &n,
                          &PyByteArray_Type, &decisions))
        return NULL;
    if (PyList_GET_SIZE(metrics) != 64 || n < 0 || n > view.len || (n & 1)) {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_ValueError, "viterbi27: 64 metrics and an even symbol count");
        return NULL;
    }
    for (int s = 0; s < 64; s++) {
        p[s] = PyLong_AsLongLong(PyList_GET_ITEM(metrics, s));
        if (p[s] == -1 && PyErr_Occurred()) {
            PyBuffer_Release(&view);
            return NULL;
        }
    }
    for (int j = 0; j < 32; j++) {
        int c1 = v27_parity((unsigned)(2 * j) & 0x4Fu);
        int c2 = v27_parity((unsigned)(2 * j) & 0x6Du) ^ 1;
        tab[j] = (1 - c1) * 2 + (1 - c2);
    }
    base = PyByteArray_GET_SIZE(decisions);
    if (PyByteArray_Resize(decisions, base + (n / 2) * 8) < 0) {
        PyBuffer_Release(&view);
        return NULL;
    }
    dst = (unsigned char *)PyByteArray_AS_STRING(decisions) + base;
    sy = (const signed char *)view.buf;
    for (Py_ssize_t i = 0; i < n; i += 2) {
        long long a = sy[i], b = sy[i + 1], m[4];
        unsigned long long d = 0;
        m[0] = a + b;
        m[1] = a - b;
        m[2] = b - a;
        m[3] = -a - b;
        for (int j = 0; j < 32; j++) {
            long long mu = m[tab[j]], x, y;
            x = p[j] + mu;
            y = p[j + 32] - mu;
            if (x >= y)
                q[2 * j] = x;
            else {
                q[2 * j] = y;
                d |= 1ull << (2 * j);
            }
            x = p[j] - mu;
            y = p[j + 32] + mu;
            if (x >= y)
                q[2 * j + 1] = x;
            else {
                q[2 * j + 1] = y;
                d |= 2ull << (2 * j);
            }
        }
        if (q[0] > (1 << 24) || q[0] < -(1 << 24)) {
            long long top = q[0];
            for (int s = 0; s < 64; s++)
                q[s] -= top;
        }
        memcpy(p, q, sizeof(p));
        for (int k = 0; k < 8; k++)
            dst[k] = (unsigned char)(d >> (8 * k));
        dst += 8;
    }
    PyBuffer_Release(&view);
    out = PyList_New(64);
    if (out == NULL)
        return NULL;
    for (int s = 0; s < 64; s++) {
        PyObject *v = PyLong_FromLongLong(p[s]);
        if (v == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, s, v);
    }
    return out;
}

static PyObject *
viterbi27_chainback(PyObject *self, PyObject *args)
{
    Py_buffer view;
    unsigned int state;
    Py_ssize_t count, steps;
    PyObject *out;
    unsigned char *o;
    const unsigned char *dec;

    (void)self;
    if (!PyArg_ParseTuple(args, "y*In:viterbi27_chainback", &view, &state, &count))
        return NULL;
    steps = view.len / 8;
    if (count < 0 || count > steps) {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_ValueError, "viterbi27_chainback: count beyond the decisions");
        return NULL;
    }
    out = PyBytes_FromStringAndSize(NULL, count);
    if (out == NULL) {
        PyBuffer_Release(&view);
        return NULL;
    }
    o = (unsigned char *)PyBytes_AS_STRING(out);
    dec = (const unsigned char *)view.buf;
    state &= 63u;
    for (Py_ssize_t t = steps - 1; t >= 0; t--) {
        unsigned bit = (dec[8 * t + (state >> 3)] >> (state & 7u)) & 1u;
        if (t < count)
            o[t] = (unsigned char)(state & 1u);
        state = (state >> 1) | (bit << 5);
    }
    PyBuffer_Release(&view);
    return out;
}

#define FASTCALL(f) (PyCFunction)(void (*)(void))(f), METH_FASTCALL

static PyMethodDef methods[] = {
    {"tc_pack", FASTCALL(tc_pack), "Pack a TC of a whole-octet layout, or None."},
    {"tm_pack", FASTCALL(tm_pack), "Pack a TM of a whole-octet layout, or None."},
    {"tc_pack_slots", FASTCALL(tc_pack_slots), "tc.pack() for a whole-octet layout, or None."},
    {"tm_pack_slots", FASTCALL(tm_pack_slots), "tm.pack() for a whole-octet layout, or None."},
    {"tc_unpack", FASTCALL(tc_unpack), "Decode a well-formed TC into cls, or None."},
    {"tm_unpack", FASTCALL(tm_unpack), "Decode a well-formed TM into cls, or None."},
    {"cbor_frame", cbor_frame, METH_O, "Length-prefixed deterministic CBOR, or None."},
    {"cbor_loads", FASTCALL(cbor_loads), "Decode one CBOR item, or return the second arg."},
    {"cbor_frame_loads", FASTCALL(cbor_frame_loads),
     "Decode the one whole length-prefixed frame data holds, or return the second arg."},
    {"crc16_ccitt", crc16_ccitt, METH_VARARGS, "CRC-16/CCITT-FALSE continuing a register."},
    {"viterbi27", viterbi27, METH_VARARGS, "K=7 r=1/2 add-compare-select on int8 soft symbols."},
    {"viterbi27_chainback", viterbi27_chainback, METH_VARARGS, "Bits traced back, oldest first."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "obsw_speedups",
    "C hot path of the obsw PUS-C packet codec (CPython only; the Python code is the "
    "definition).",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC
PyInit_obsw_speedups(void)
{
    PyObject *m;
    PyObject **names[] = {&s_apid, &s_service, &s_subtype, &s_data, &s_seq_count,
                          &s_ack, &s_source_id, &s_seq_flags, &s_config, &s_message_counter,
                          &s_destination_id, &s_time, &s_time_ref};
    const char *texts[] = {"apid", "service", "subtype", "data", "seq_count",
                           "ack", "source_id", "seq_flags", "config", "message_counter",
                           "destination_id", "time", "time_ref"};

    crc_init();
    for (size_t i = 0; i < sizeof(names) / sizeof(names[0]); i++) {
        if (*names[i] == NULL && (*names[i] = PyUnicode_InternFromString(texts[i])) == NULL)
            return NULL;
    }
    if (empty_tuple == NULL && (empty_tuple = PyTuple_New(0)) == NULL)
        return NULL;
    m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    if (PyModule_AddIntConstant(m, "API", API_VERSION) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
