/* SPDX-License-Identifier: MIT */
/* glTF accessor decoding (spec §3.6.2), KHR_mesh_quantization component types and
 * EXT_meshopt_compression bufferViews (streams by libmeshoptimizer, filters by gltf_meshopt.c).
 * tinygltf parses accessors but applies neither sparse substitution nor meshopt, and accepts
 * accessors without bufferView; all of that is done here, with every byte range checked before
 * it is read. */
#include <math.h>
#include <string.h>
#include <meshoptimizer.h>
#include "gltf_accessor.h"
#include "gltf_meshopt.h"

mk_result mk_gltf_reader_init(mk_gltf_reader *r, const mk_gltf_doc *doc, mk_arena *arena, mk_error *err)
{
    memset(r, 0, sizeof *r);
    r->doc = doc;
    r->arena = arena;
    r->decoded = mk_arena_array(arena, doc->view_count + 1u, sizeof *r->decoded);
    r->decoded_size = mk_arena_array(arena, doc->view_count + 1u, sizeof *r->decoded_size);
    if (!r->decoded || !r->decoded_size) return mk_error_oom(err, "glTF bufferView cache");
    return MK_OK;
}

static int component_size(int type)
{
    switch (type) {
    case MK_GLTF_BYTE: case MK_GLTF_UNSIGNED_BYTE: return 1;
    case MK_GLTF_SHORT: case MK_GLTF_UNSIGNED_SHORT: return 2;
    case MK_GLTF_UNSIGNED_INT: case MK_GLTF_FLOAT: return 4;
    default: return 0;
    }
}

/* Decodes an EXT_meshopt_compression view. The byte-stream decoders of libmeshoptimizer
 * validate the compressed stream themselves (they are meant for untrusted input) but assert on
 * their size arguments, so those are checked here first (extension README, "Compressing buffer
 * views"). The filters are ours (gltf_meshopt.c): the library's round some octahedral normals
 * one step away from the README's formula. */
static mk_result decode_meshopt(mk_gltf_reader *r, int32_t vi, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    const mk_gltf_view *v = &d->views[vi];
    if (v->mo_buffer < 0 || (uint32_t)v->mo_buffer >= d->buffer_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: EXT_meshopt_compression buffer %d out of range", vi, v->mo_buffer);
    const mk_gltf_buffer *b = &d->buffers[v->mo_buffer];
    if (v->mo_offset > b->size || v->mo_length > b->size - v->mo_offset)
        return mk_error_set(err, MK_ERROR_TRUNCATED, UINT64_MAX,
                            "bufferView %d: EXT_meshopt_compression range %llu+%llu exceeds buffer %d (%llu bytes)", vi,
                            (unsigned long long)v->mo_offset, (unsigned long long)v->mo_length, v->mo_buffer,
                            (unsigned long long)b->size);
    uint64_t count = v->mo_count, stride = v->mo_stride;
    if (count == 0 || stride == 0 || count > (1ull << 32) || stride > 256)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: EXT_meshopt_compression count %llu / byteStride %llu invalid",
                            vi, (unsigned long long)count, (unsigned long long)stride);
    uint64_t bytes = count * stride;
    uint64_t alloc = bytes > v->length ? bytes : v->length;
    uint8_t *out = mk_arena_alloc(r->arena, (size_t)alloc);
    if (!out) return mk_error_oom(err, "meshopt bufferView");
    const unsigned char *src = b->data + v->mo_offset;
    int rc;
    switch (v->mo_mode) {
    case MK_MESHOPT_ATTRIBUTES:
        if (stride % 4 != 0)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: meshopt ATTRIBUTES byteStride %llu not a multiple of 4", vi, (unsigned long long)stride);
        rc = meshopt_decodeVertexBuffer(out, (size_t)count, (size_t)stride, src, (size_t)v->mo_length);
        if (rc == 0) {
            if (v->mo_filter == MK_MESHOPT_OCTAHEDRAL) {
                if (stride != 4 && stride != 8)
                    return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: OCTAHEDRAL filter needs byteStride 4 or 8", vi);
                mk_meshopt_filter_octahedral(out, (size_t)count, (size_t)stride);
            } else if (v->mo_filter == MK_MESHOPT_QUATERNION) {
                if (stride != 8)
                    return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: QUATERNION filter needs byteStride 8", vi);
                mk_meshopt_filter_quaternion(out, (size_t)count, (size_t)stride);
            } else if (v->mo_filter == MK_MESHOPT_EXPONENTIAL) {
                mk_meshopt_filter_exponential(out, (size_t)count, (size_t)stride);
            } else if (v->mo_filter != MK_MESHOPT_NONE) {
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: unknown meshopt filter", vi);
            }
        }
        break;
    case MK_MESHOPT_TRIANGLES:
        if ((stride != 2 && stride != 4) || count % 3 != 0)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: meshopt TRIANGLES needs byteStride 2/4 and a count divisible by 3", vi);
        rc = meshopt_decodeIndexBuffer(out, (size_t)count, (size_t)stride, src, (size_t)v->mo_length);
        break;
    case MK_MESHOPT_INDICES:
        if (stride != 2 && stride != 4)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: meshopt INDICES needs byteStride 2 or 4", vi);
        rc = meshopt_decodeIndexSequence(out, (size_t)count, (size_t)stride, src, (size_t)v->mo_length);
        break;
    default:
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: unknown EXT_meshopt_compression mode", vi);
    }
    if (rc != 0)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: EXT_meshopt_compression data is corrupt (decoder error %d)", vi, rc);
    r->decoded[vi] = out;
    r->decoded_size[vi] = alloc;
    return MK_OK;
}

mk_result mk_gltf_view_bytes(mk_gltf_reader *r, int32_t vi, const uint8_t **data, uint64_t *size, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    if (vi < 0 || (uint32_t)vi >= d->view_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d out of range (%u bufferViews)", vi, d->view_count);
    const mk_gltf_view *v = &d->views[vi];
    if (v->meshopt) {
        if (!r->decoded[vi]) {
            mk_result res = decode_meshopt(r, vi, err);
            if (res != MK_OK) return res;
        }
        *data = r->decoded[vi];
        *size = v->length < r->decoded_size[vi] ? v->length : r->decoded_size[vi];
        return MK_OK;
    }
    if (v->buffer < 0 || (uint32_t)v->buffer >= d->buffer_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "bufferView %d: buffer %d out of range", vi, v->buffer);
    const mk_gltf_buffer *b = &d->buffers[v->buffer];
    if (v->offset > b->size || v->length > b->size - v->offset)
        return mk_error_set(err, MK_ERROR_TRUNCATED, UINT64_MAX,
                            "bufferView %d: bytes %llu..%llu exceed buffer %d (%llu bytes)", vi,
                            (unsigned long long)v->offset, (unsigned long long)(v->offset + v->length), v->buffer,
                            (unsigned long long)b->size);
    *data = b->data + v->offset;
    *size = v->length;
    return MK_OK;
}

/* One component as float. Normalized integers follow the spec's conversion table (animation
 * samplers; KHR_mesh_quantization has the same): f = max(c / 127.0, -1.0), c / 255.0,
 * max(c / 32767.0, -1.0), c / 65535.0; the float division rounds once, so these are the
 * correctly rounded values.
 * `normalized` is ignored for FLOAT (the spec forbids it there; the value is unambiguous).
 * UNSIGNED_INT is never float data (mk_gltf_read_floats refuses it); here it only reads sparse
 * indices, which are not normalized. */
static float read_component(const uint8_t *p, int type, int normalized)
{
    switch (type) {
    case MK_GLTF_BYTE: { int8_t c; memcpy(&c, p, 1); return normalized ? fmaxf(c / 127.0f, -1.0f) : (float)c; }
    case MK_GLTF_UNSIGNED_BYTE: { uint8_t c = p[0]; return normalized ? c / 255.0f : (float)c; }
    case MK_GLTF_SHORT: { int16_t c; memcpy(&c, p, 2); return normalized ? fmaxf(c / 32767.0f, -1.0f) : (float)c; }
    case MK_GLTF_UNSIGNED_SHORT: { uint16_t c; memcpy(&c, p, 2); return normalized ? c / 65535.0f : (float)c; }
    case MK_GLTF_UNSIGNED_INT: { uint32_t c; memcpy(&c, p, 4); return (float)c; }
    default: { float c; memcpy(&c, p, 4); return c; }
    }
}

/* Elements [0, count) of `stride`-spaced data at `offset` of a view: range check. */
static mk_result check_range(int32_t accessor, int32_t vi, uint64_t view_size, uint64_t offset, uint64_t stride,
                             uint64_t elem, uint64_t count, const char *what, mk_error *err)
{
    if (count == 0) return MK_OK;
    if (offset > view_size || (count - 1) > (view_size - offset) / (stride ? stride : 1)
        || (count - 1) * stride + elem > view_size - offset)
        return mk_error_set(err, MK_ERROR_TRUNCATED, UINT64_MAX,
                            "%s: accessor %d needs %llu elements of %llu bytes (stride %llu) from byte %llu of bufferView %d, which has %llu bytes",
                            what, accessor, (unsigned long long)count, (unsigned long long)elem, (unsigned long long)stride,
                            (unsigned long long)offset, vi, (unsigned long long)view_size);
    return MK_OK;
}

mk_result mk_gltf_read_floats(mk_gltf_reader *r, int32_t index, int components, const char *what,
                              float **out, uint64_t *count_out, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    mk_result res;
    if (index < 0 || (uint32_t)index >= d->accessor_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d out of range (%u accessors)", what, index, d->accessor_count);
    const mk_gltf_accessor *a = &d->accessors[index];
    int cs = component_size(a->component_type);
    if (!cs)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d has unsupported componentType %d", what, index, a->component_type);
    if (a->component_type == MK_GLTF_UNSIGNED_INT)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d has componentType 5125 (UNSIGNED_INT), which glTF allows for indices only",
                            what, index);
    if (a->components != components)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d has %d components, expected %d", what, index, a->components, components);
    /* 2^28 elements x 4 floats stays far below size_t limits; real assets are much smaller. */
    if (a->count > (1u << 28))
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: accessor %d count %llu too large", what, index, (unsigned long long)a->count);
    uint64_t n = a->count, elem = (uint64_t)cs * (uint64_t)components;
    /* An accessor without bufferView costs no file bytes, so bound it separately: 16M
     * elements is far beyond any morph target yet keeps a hostile count from asking for GBs. */
    if (a->view < 0 && n > (1u << 24))
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: accessor %d without bufferView has %llu elements (limit 16M)",
                            what, index, (unsigned long long)n);
    const uint8_t *bytes = NULL; uint64_t size = 0, stride = elem;
    if (a->view >= 0) {
        /* Check the byte range before allocating, so the count cannot exceed the data. */
        if ((res = mk_gltf_view_bytes(r, a->view, &bytes, &size, err)) != MK_OK) return res;
        stride = d->views[a->view].stride ? d->views[a->view].stride : elem;
        if (stride < elem)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d: byteStride %llu smaller than its %llu-byte elements",
                                what, index, (unsigned long long)stride, (unsigned long long)elem);
        if ((res = check_range(index, a->view, size, a->offset, stride, elem, n, what, err)) != MK_OK) return res;
    }
    float *f = mk_arena_array(r->arena, (size_t)(n ? n : 1) * (size_t)components, sizeof(float));
    if (!f) return mk_error_oom(err, what);

    if (a->view >= 0) {
        for (uint64_t i = 0; i < n; i++) {
            const uint8_t *p = bytes + a->offset + i * stride;
            for (int c = 0; c < components; c++) f[i * components + c] = read_component(p + c * cs, a->component_type, a->normalized);
        }
    } /* else: zeros (spec §3.6.2.3), already zeroed by the arena */

    if (a->sparse) {
        uint64_t sc = a->sparse_count;
        int is = component_size(a->sparse_indices_type);
        if (sc == 0 || sc > n)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d: sparse count %llu must be in 1..%llu",
                                what, index, (unsigned long long)sc, (unsigned long long)n);
        if (a->sparse_indices_type != MK_GLTF_UNSIGNED_BYTE && a->sparse_indices_type != MK_GLTF_UNSIGNED_SHORT
            && a->sparse_indices_type != MK_GLTF_UNSIGNED_INT)
            return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d: sparse indices componentType %d invalid",
                                what, index, a->sparse_indices_type);
        const uint8_t *ib, *vb; uint64_t isz, vsz;
        if ((res = mk_gltf_view_bytes(r, a->sparse_indices_view, &ib, &isz, err)) != MK_OK) return res;
        if ((res = mk_gltf_view_bytes(r, a->sparse_values_view, &vb, &vsz, err)) != MK_OK) return res;
        if ((res = check_range(index, a->sparse_indices_view, isz, a->sparse_indices_offset, (uint64_t)is, (uint64_t)is, sc, what, err)) != MK_OK) return res;
        if ((res = check_range(index, a->sparse_values_view, vsz, a->sparse_values_offset, elem, elem, sc, what, err)) != MK_OK) return res;
        uint64_t prev = 0;
        for (uint64_t k = 0; k < sc; k++) {
            uint64_t at = (uint64_t)read_component(ib + a->sparse_indices_offset + k * is, a->sparse_indices_type, 0);
            if (a->sparse_indices_type == MK_GLTF_UNSIGNED_INT) {
                uint32_t u; memcpy(&u, ib + a->sparse_indices_offset + k * is, 4); at = u;   /* exact, not via float */
            }
            /* The spec: indices MUST strictly increase (so no duplicates) and be < count. */
            if (at >= n)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX,
                                    "%s: accessor %d: sparse index %llu (entry %llu) is past the accessor's %llu elements",
                                    what, index, (unsigned long long)at, (unsigned long long)k, (unsigned long long)n);
            if (k > 0 && at <= prev)
                return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX,
                                    "%s: accessor %d: sparse index %llu (entry %llu) after %llu: sparse indices must strictly increase",
                                    what, index, (unsigned long long)at, (unsigned long long)k, (unsigned long long)prev);
            prev = at;
            const uint8_t *p = vb + a->sparse_values_offset + k * elem;
            for (int c = 0; c < components; c++) f[at * components + c] = read_component(p + c * cs, a->component_type, a->normalized);
        }
    }
    for (uint64_t i = 0; i < n * (uint64_t)components; i++)
        if (!isfinite(f[i]))
            return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX, "%s: accessor %d element %llu is NaN or infinite",
                                what, index, (unsigned long long)(i / components));
    *out = f;
    *count_out = n;
    return MK_OK;
}

mk_result mk_gltf_read_indices(mk_gltf_reader *r, int32_t index, const char *what, uint32_t **out,
                               uint64_t *count_out, mk_error *err)
{
    const mk_gltf_doc *d = r->doc;
    mk_result res;
    if (index < 0 || (uint32_t)index >= d->accessor_count)
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: accessor %d out of range (%u accessors)", what, index, d->accessor_count);
    const mk_gltf_accessor *a = &d->accessors[index];
    int t = a->component_type;
    if (a->components != 1 || (t != MK_GLTF_UNSIGNED_BYTE && t != MK_GLTF_UNSIGNED_SHORT && t != MK_GLTF_UNSIGNED_INT))
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "%s: index accessor %d must be SCALAR unsigned byte/short/int", what, index);
    if (a->count > (1u << 30))
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: accessor %d count %llu too large", what, index, (unsigned long long)a->count);
    uint64_t n = a->count;
    int cs = component_size(t);
    if (a->view < 0 && n > (1u << 24))
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "%s: index accessor %d without bufferView has %llu elements (limit 16M)",
                            what, index, (unsigned long long)n);
    const uint8_t *bytes = NULL; uint64_t size = 0, stride = (uint64_t)cs;
    if (a->view >= 0) {
        if ((res = mk_gltf_view_bytes(r, a->view, &bytes, &size, err)) != MK_OK) return res;
        stride = d->views[a->view].stride ? d->views[a->view].stride : (uint64_t)cs;
        if ((res = check_range(index, a->view, size, a->offset, stride, (uint64_t)cs, n, what, err)) != MK_OK) return res;
    }
    uint32_t *u = mk_arena_array(r->arena, (size_t)(n ? n : 1), sizeof(uint32_t));
    if (!u) return mk_error_oom(err, what);
    if (a->view >= 0) {
        for (uint64_t i = 0; i < n; i++) {
            const uint8_t *p = bytes + a->offset + i * stride;
            if (cs == 1) u[i] = p[0];
            else if (cs == 2) { uint16_t s; memcpy(&s, p, 2); u[i] = s; }
            else memcpy(&u[i], p, 4);
        }
    }
    if (a->sparse) {
        /* Sparse index accessors are legal but odd; decode through the float path would lose
         * precision, so treat them as unsupported rather than guess. */
        return mk_error_set(err, MK_ERROR_UNSUPPORTED, UINT64_MAX, "%s: sparse index accessor %d is not supported", what, index);
    }
    *out = u;
    *count_out = n;
    return MK_OK;
}
