// SPDX-License-Identifier: MIT
// glTF parsing shim: tinygltf (JSON, GLB, buffers, data URIs) + libdraco, exposed to the C
// importer as the plain structs of gltf_doc.h.
//
// Why tinygltf is compiled here and not linked from Debian's libtinygltf.so: the packaged
// library has no Draco support, and its inline TinyGLTF
// constructor references the stb image writer unless every TU agrees on the same
// TINYGLTF_NO_STB_* macros. This is the only TU that defines TINYGLTF_IMPLEMENTATION; it does
// not link -ltinygltf.
//
// Why Draco is decoded here with libdraco and not by tinygltf's TINYGLTF_ENABLE_DRACO path:
// tinygltf 2.7.0's ParseDracoExtension indexes model->bufferViews / buffers / accessors without
// range checks, reads the bufferView without checking byteOffset + byteLength against the
// buffer, dereferences GetAttributeByUniqueId() without a null check, copies up to 255
// components into a 4-element stack array, and ignores its own failures. A truncated or
// byte-flipped file therefore crashes it. The decode below does the same work with every
// index, range and count checked, and fails with a message naming the primitive.
//
// Meshopt fallback buffers (EXT_meshopt_compression "fallback": true) have a byteLength but no
// data; tinygltf would reject them, so they are replaced by a 1-byte data URI before parsing
// and reported as empty buffers (the C side decodes the compressed views instead).
//
// External files: tinygltf looks a buffer URI up in the base directory and then in "." (the
// process's working directory), so a .gltf copied without its .bin silently read a same-named
// file from wherever the tool was started. The loader is given a marker instead of the real
// directory; the file callbacks accept only paths under the marker (the "." lookup never is),
// resolve the URI against the glTF file's folder themselves and refuse absolute paths and URI
// schemes other than data: (tinygltf decodes those itself). Images are never read
// (TINYGLTF_NO_EXTERNAL_IMAGE), so buffers are the only external files.

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_USE_CPP14
#include <tiny_gltf.h>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <set>
#include <string>
#include <vector>

#include "gltf_doc.h"

namespace {

struct Impl {
    tinygltf::Model model;
    std::set<int> fallback_buffers;   // buffers replaced before parsing (no data)
    // primitive (mesh, index) -> its "indices" accessor, removed from the JSON because the
    // accessor has no bufferView (Draco-compressed, or all zeros): tinygltf 2.7.0 refuses
    // index accessors without bufferView although the spec allows them (§3.6.2.3).
    std::map<std::pair<int, int>, int> hidden_indices;
};

// What tinygltf gets as its base directory: paths it builds from a URI start with this plus
// '/'; its fallback lookup in "." starts with "./" and so never matches.
const char kBaseMarker[] = "<glTF folder>";

struct FsContext {
    std::string base_dir;          // the glTF file's folder ("" = the working directory)
    bool allow_files;
    uint64_t max_size;
    std::string failure;           // first refused or missing external file, for the error
    mk_result failure_code = MK_OK;
    void (*file_read)(void *user, const char *path) = nullptr;
    void *file_read_user = nullptr;
};

// RFC 3986 scheme: a letter, then letters, digits, '+', '-', '.', up to ':' (before any '/').
bool has_scheme(const std::string &uri)
{
    if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return false;
    for (size_t i = 1; i < uri.size(); i++) {
        unsigned char c = static_cast<unsigned char>(uri[i]);
        if (c == ':') return true;
        if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return false;
    }
    return false;
}

void fail_once(FsContext *ctx, mk_result code, const std::string &message)
{
    if (ctx->failure_code != MK_OK) return;
    ctx->failure_code = code;
    ctx->failure = message;
}

// The file a tinygltf path stands for, or "" (after recording why) when it must not be read;
// *uri is the URI it came from (percent-decoded by tinygltf). Relative references, ".."
// included, resolve against the glTF file's folder as the spec says; absolute paths and other
// schemes are refused, so a downloaded .gltf cannot pull in an arbitrary file of the machine.
std::string resolve(FsContext *ctx, const std::string &path, std::string *uri_out)
{
    const std::string prefix = std::string(kBaseMarker) + "/";
    if (path.compare(0, prefix.size(), prefix) != 0) return "";  // tinygltf's "." fallback
    const std::string uri = *uri_out = path.substr(prefix.size());
    const std::string named = "buffer URI '" + uri + "'";
    if (!ctx->allow_files) {
        fail_once(ctx, MK_ERROR_PARSE, named + ": external files are not allowed when loading from memory");
        return "";
    }
    if (uri.empty() || uri.find('\0') != std::string::npos) {
        fail_once(ctx, MK_ERROR_PARSE, named + ": not a file name");
        return "";
    }
    if (uri[0] == '/' || uri[0] == '\\') {
        fail_once(ctx, MK_ERROR_UNSUPPORTED, named + ": absolute paths are not allowed (external files resolve against the glTF file's folder)");
        return "";
    }
    if (has_scheme(uri)) {
        fail_once(ctx, MK_ERROR_UNSUPPORTED, named + ": URI scheme '" + uri.substr(0, uri.find(':') + 1) +
                                                 "' is not supported (only data: URIs and paths relative to the glTF file's folder)");
        return "";
    }
    if (ctx->base_dir.empty()) return uri;
    return ctx->base_dir + (ctx->base_dir.back() == '/' ? "" : "/") + uri;
}

bool fs_exists(const std::string &path, void *user)
{
    FsContext *ctx = static_cast<FsContext *>(user);
    std::string uri, file = resolve(ctx, path, &uri);
    if (file.empty()) return false;
    FILE *f = std::fopen(file.c_str(), "rb");
    if (!f) {
        fail_once(ctx, MK_ERROR_IO, "buffer URI '" + uri + "': cannot open '" + file + "' (" + std::strerror(errno) +
                                        "); external files resolve against the glTF file's folder only");
        return false;
    }
    std::fclose(f);
    return true;
}

std::string fs_expand(const std::string &path, void *) { return path; }

// Reads a whole external file, refusing anything larger than the configured bound so a
// hostile URI (e.g. /dev/zero) cannot exhaust memory.
bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    FsContext *ctx = static_cast<FsContext *>(user);
    std::string uri, file = resolve(ctx, path, &uri);
    if (file.empty()) {
        if (err) *err += "external file '" + path + "' refused\n";
        return false;
    }
    FILE *f = std::fopen(file.c_str(), "rb");
    if (!f) {
        fail_once(ctx, MK_ERROR_IO, "buffer URI '" + uri + "': cannot open '" + file + "' (" + std::strerror(errno) + ")");
        if (err) *err += "cannot open '" + file + "'\n";
        return false;
    }
    out->clear();
    unsigned char chunk[65536];
    size_t n;
    while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (ctx->max_size && out->size() + n > ctx->max_size) {
            std::fclose(f);
            if (err) *err += "'" + file + "' exceeds the input size limit\n";
            return false;
        }
        out->insert(out->end(), chunk, chunk + n);
    }
    bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) {
        if (err) *err += "read error on '" + file + "'\n";
        return false;
    }
    if (ctx->file_read) ctx->file_read(ctx->file_read_user, file.c_str());
    return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err) *err += "writing is not supported by the importer\n";
    return false;
}

// Images are irrelevant to morphs: accept them without decoding.
bool dummy_image_loader(tinygltf::Image *, const int, std::string *, std::string *, int, int,
                        const unsigned char *, int, void *)
{
    return true;
}

uint32_t rd32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

void wr32(std::string &s, uint32_t v)
{
    for (int i = 0; i < 4; ++i) s.push_back((char)((v >> (8 * i)) & 0xff));
}

// Removes primitive.indices that name an accessor without bufferView (see Impl).
bool hide_viewless_indices(nlohmann::json &j, std::map<std::pair<int, int>, int> &hidden)
{
    auto acc = j.find("accessors");
    auto meshes = j.find("meshes");
    if (acc == j.end() || !acc->is_array() || meshes == j.end() || !meshes->is_array()) return false;
    bool changed = false;
    for (size_t m = 0; m < meshes->size(); ++m) {
        nlohmann::json &mesh = (*meshes)[m];
        if (!mesh.is_object()) continue;
        auto prims = mesh.find("primitives");
        if (prims == mesh.end() || !prims->is_array()) continue;
        for (size_t p = 0; p < prims->size(); ++p) {
            nlohmann::json &prim = (*prims)[p];
            if (!prim.is_object()) continue;
            auto ind = prim.find("indices");
            if (ind == prim.end() || !ind->is_number_unsigned()) continue;
            uint64_t a = ind->get<uint64_t>();
            if (a >= acc->size() || !(*acc)[a].is_object() || (*acc)[a].contains("bufferView")) continue;
            hidden[std::make_pair((int)m, (int)p)] = (int)a;
            prim.erase(ind);
            changed = true;
        }
    }
    return changed;
}

// Deepest array/object nesting of a JSON text (strings skipped). nlohmann's serializer and
// tinygltf's extras conversion recurse per level, so a hostile file with 100k nested arrays
// would overflow the stack; real glTF nests about 10 levels (extras a few more).
size_t json_depth(const std::string &t)
{
    size_t depth = 0, deepest = 0;
    bool in_string = false;
    for (size_t i = 0; i < t.size(); ++i) {
        char c = t[i];
        if (in_string) {
            if (c == '\\') ++i;
            else if (c == '"') in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

// Replaces meshopt fallback buffers in the JSON. Returns false when nothing had to change.
bool patch_fallback_buffers(nlohmann::json &j, std::set<int> &fallback)
{
    if (!j.is_object()) return false;
    auto it = j.find("buffers");
    if (it == j.end() || !it->is_array()) return false;
    bool changed = false;
    for (size_t i = 0; i < it->size(); ++i) {
        nlohmann::json &b = (*it)[i];
        if (!b.is_object() || b.contains("uri")) continue;
        auto ext = b.find("extensions");
        if (ext == b.end() || !ext->is_object()) continue;
        bool is_fallback = false;
        for (const char *name : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
            auto e = ext->find(name);
            if (e != ext->end() && e->is_object()) {
                auto fb = e->find("fallback");
                if (fb != e->end() && fb->is_boolean() && fb->get<bool>()) is_fallback = true;
            }
        }
        if (!is_fallback) continue;
        b["byteLength"] = 1;
        b["uri"] = "data:application/octet-stream;base64,AA==";
        fallback.insert((int)i);
        changed = true;
    }
    return changed;
}

template <typename T> T *arena_array(mk_arena *arena, size_t n)
{
    T *p = static_cast<T *>(mk_arena_array(arena, n ? n : 1, sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

const char *arena_str(mk_arena *arena, const std::string &s)
{
    char *p = mk_arena_strndup(arena, s.data(), s.size());
    if (!p) throw std::bad_alloc();
    return p;
}

int components_of(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

void copy_attributes(mk_arena *arena, const std::map<std::string, int> &src, uint32_t *count,
                     mk_gltf_attribute **out)
{
    *count = (uint32_t)src.size();
    *out = arena_array<mk_gltf_attribute>(arena, src.size());
    uint32_t k = 0;
    for (const auto &kv : src) {
        (*out)[k].semantic = arena_str(arena, kv.first);
        (*out)[k].accessor = kv.second;
        ++k;
    }
}

// extras.targetNames as a string array (ignores anything else).
void copy_target_names(mk_arena *arena, const tinygltf::Value &extras, uint32_t *count,
                       const char ***out)
{
    *count = 0;
    *out = nullptr;
    if (!extras.IsObject() || !extras.Has("targetNames")) return;
    const tinygltf::Value &names = extras.Get("targetNames");
    if (!names.IsArray()) return;
    size_t n = names.ArrayLen();
    *out = arena_array<const char *>(arena, n);
    for (size_t i = 0; i < n; ++i) {
        const tinygltf::Value &v = names.Get((int)i);
        (*out)[i] = v.IsString() ? arena_str(arena, v.Get<std::string>()) : arena_str(arena, "");
    }
    *count = (uint32_t)n;
}

// Value as a non-negative integer (tinygltf keeps JSON numbers as int or real).
bool value_uint(const tinygltf::Value &v, uint64_t *out)
{
    if (v.IsInt()) {
        if (v.Get<int>() < 0) return false;
        *out = (uint64_t)v.Get<int>();
        return true;
    }
    if (v.IsNumber()) {
        double d = v.GetNumberAsDouble();
        if (!(d >= 0 && d <= 9.0e15) || d != (double)(uint64_t)d) return false;
        *out = (uint64_t)d;
        return true;
    }
    return false;
}

void copy_meshopt(const tinygltf::BufferView &bv, mk_gltf_view *v)
{
    const tinygltf::Value *ext = nullptr;
    for (const char *name : {"EXT_meshopt_compression"}) {
        auto it = bv.extensions.find(name);
        if (it != bv.extensions.end()) ext = &it->second;
    }
    if (!ext) return;
    v->meshopt = 1;
    v->mo_buffer = -1;
    v->mo_mode = -1;
    v->mo_filter = MK_MESHOPT_NONE;
    if (!ext->IsObject()) return;
    uint64_t u;
    if (ext->Has("buffer") && value_uint(ext->Get("buffer"), &u) && u < 0x7fffffff) v->mo_buffer = (int32_t)u;
    if (ext->Has("byteOffset") && value_uint(ext->Get("byteOffset"), &u)) v->mo_offset = u;
    if (ext->Has("byteLength") && value_uint(ext->Get("byteLength"), &u)) v->mo_length = u;
    if (ext->Has("byteStride") && value_uint(ext->Get("byteStride"), &u) && u < 0x10000) v->mo_stride = (uint32_t)u;
    if (ext->Has("count") && value_uint(ext->Get("count"), &u)) v->mo_count = u;
    if (ext->Has("mode") && ext->Get("mode").IsString()) {
        std::string m = ext->Get("mode").Get<std::string>();
        v->mo_mode = m == "ATTRIBUTES" ? MK_MESHOPT_ATTRIBUTES : m == "TRIANGLES" ? MK_MESHOPT_TRIANGLES
                   : m == "INDICES" ? MK_MESHOPT_INDICES : -1;
    }
    if (ext->Has("filter") && ext->Get("filter").IsString()) {
        std::string f = ext->Get("filter").Get<std::string>();
        v->mo_filter = f == "NONE" ? MK_MESHOPT_NONE : f == "OCTAHEDRAL" ? MK_MESHOPT_OCTAHEDRAL
                     : f == "QUATERNION" ? MK_MESHOPT_QUATERNION : f == "EXPONENTIAL" ? MK_MESHOPT_EXPONENTIAL : -1;
    }
}

// Normalized-integer decode of glTF (§3.11 table / KHR_mesh_quantization).
float normalize_component(float v, draco::DataType t)
{
    switch (t) {
    case draco::DT_INT8: return std::max(v / 127.0f, -1.0f);
    case draco::DT_UINT8: return v / 255.0f;
    case draco::DT_INT16: return std::max(v / 32767.0f, -1.0f);
    case draco::DT_UINT16: return v / 65535.0f;
    default: return v;
    }
}

// Decodes one KHR_draco_mesh_compression primitive. Returns "" or an error message.
std::string decode_draco(mk_arena *arena, const tinygltf::Model &m, const tinygltf::Primitive &p,
                         const tinygltf::Value &ext, std::set<int> &fallback, mk_gltf_primitive *out)
{
    out->draco = 1;
    if (!ext.IsObject()) return "extension is not an object";
    uint64_t view_index;
    if (!ext.Has("bufferView") || !value_uint(ext.Get("bufferView"), &view_index))
        return "missing or invalid bufferView";
    if (view_index >= m.bufferViews.size()) return "bufferView " + std::to_string(view_index) + " out of range";
    const tinygltf::BufferView &bv = m.bufferViews[view_index];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size() || fallback.count(bv.buffer))
        return "bufferView " + std::to_string(view_index) + " has an invalid buffer";
    const tinygltf::Buffer &buf = m.buffers[bv.buffer];
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
        return "bufferView " + std::to_string(view_index) + " exceeds its buffer";
    if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) return "missing attributes";
    if (p.mode != -1 && p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP)
        return "mode must be TRIANGLES or TRIANGLE_STRIP";

    draco::DecoderBuffer db;
    db.Init(reinterpret_cast<const char *>(buf.data.data() + bv.byteOffset), bv.byteLength);
    auto type = draco::Decoder::GetEncodedGeometryType(&db);
    if (!type.ok() || type.value() != draco::TRIANGULAR_MESH) return "not a Draco triangle mesh";
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&db);
    if (!decoded.ok()) return "Draco decode failed: " + decoded.status().error_msg_string();
    const std::unique_ptr<draco::Mesh> &mesh = decoded.value();
    if (!mesh) return "Draco decode returned no mesh";
    uint64_t points = mesh->num_points(), faces = mesh->num_faces();
    if (points > 0x7fffffff || faces > 0x7fffffff / 3) return "Draco mesh too large";

    out->draco_point_count = (uint32_t)points;
    out->draco_index_count = (uint32_t)(faces * 3);
    out->draco_indices = arena_array<uint32_t>(arena, faces * 3);
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
        const draco::Mesh::Face &face = mesh->face(f);
        for (int k = 0; k < 3; ++k) {
            uint32_t v = face[k].value();
            if (v >= points) return "Draco face index out of range";
            out->draco_indices[(size_t)f.value() * 3 + k] = v;
        }
    }

    const tinygltf::Value::Object &attrs = ext.Get("attributes").Get<tinygltf::Value::Object>();
    out->draco_attributes = arena_array<mk_gltf_draco_attribute>(arena, attrs.size());
    out->draco_attribute_count = 0;
    for (const auto &kv : attrs) {
        uint64_t uid;
        if (!value_uint(kv.second, &uid) || uid > 0xffffffffu) return "attribute " + kv.first + " has an invalid id";
        auto base = p.attributes.find(kv.first);
        if (base == p.attributes.end()) return "attribute " + kv.first + " is not an attribute of the primitive";
        const draco::PointAttribute *a = mesh->GetAttributeByUniqueId((uint32_t)uid);
        if (!a) return "attribute " + kv.first + ": no Draco attribute with unique id " + std::to_string(uid);
        int nc = a->num_components();
        if (nc < 1 || nc > 4) return "attribute " + kv.first + " has " + std::to_string(nc) + " components";
        bool normalize = false;
        if (base->second >= 0 && (size_t)base->second < m.accessors.size()) {
            const tinygltf::Accessor &acc = m.accessors[base->second];
            // Draco keeps integer attributes as integers; the accessor says whether they are
            // normalized in glTF (KHR_mesh_quantization + Draco).
            normalize = acc.normalized && !a->normalized();
        }
        mk_gltf_draco_attribute *da = &out->draco_attributes[out->draco_attribute_count++];
        da->semantic = arena_str(arena, kv.first);
        da->components = (uint32_t)nc;
        da->values = arena_array<float>(arena, points * (size_t)nc);
        float tmp[4];
        for (draco::PointIndex i(0); i < mesh->num_points(); ++i) {
            draco::AttributeValueIndex vi = a->mapped_index(i);
            if (vi.value() >= a->size()) return "attribute " + kv.first + " maps a point out of range";
            if (!a->ConvertValue<float>(vi, (int8_t)nc, tmp)) return "attribute " + kv.first + " cannot be converted";
            for (int c = 0; c < nc; ++c)
                da->values[(size_t)i.value() * nc + c] = normalize ? normalize_component(tmp[c], a->data_type()) : tmp[c];
        }
    }
    return "";
}

void convert(mk_arena *arena, Impl *impl, mk_gltf_doc *d, std::string *err)
{
    const tinygltf::Model &m = impl->model;

    d->buffer_count = (uint32_t)m.buffers.size();
    d->buffers = arena_array<mk_gltf_buffer>(arena, m.buffers.size());
    for (size_t i = 0; i < m.buffers.size(); ++i) {
        if (impl->fallback_buffers.count((int)i)) continue;   // no data: size 0
        d->buffers[i].data = m.buffers[i].data.data();
        d->buffers[i].size = m.buffers[i].data.size();
    }

    d->view_count = (uint32_t)m.bufferViews.size();
    d->views = arena_array<mk_gltf_view>(arena, m.bufferViews.size());
    for (size_t i = 0; i < m.bufferViews.size(); ++i) {
        const tinygltf::BufferView &bv = m.bufferViews[i];
        mk_gltf_view *v = &d->views[i];
        v->buffer = bv.buffer;
        v->offset = bv.byteOffset;
        v->length = bv.byteLength;
        v->stride = bv.byteStride > 0xffff ? 0xffff : (uint32_t)bv.byteStride;
        copy_meshopt(bv, v);
    }

    d->accessor_count = (uint32_t)m.accessors.size();
    d->accessors = arena_array<mk_gltf_accessor>(arena, m.accessors.size());
    for (size_t i = 0; i < m.accessors.size(); ++i) {
        const tinygltf::Accessor &a = m.accessors[i];
        mk_gltf_accessor *o = &d->accessors[i];
        o->view = a.bufferView;
        o->offset = a.byteOffset;
        o->component_type = a.componentType;
        o->components = components_of(a.type);
        o->normalized = a.normalized;
        o->count = a.count;
        o->sparse = a.sparse.isSparse;
        if (a.sparse.isSparse) {
            o->sparse_count = a.sparse.count < 0 ? UINT64_MAX : (uint64_t)a.sparse.count;
            o->sparse_indices_view = a.sparse.indices.bufferView;
            o->sparse_indices_offset = a.sparse.indices.byteOffset < 0 ? UINT64_MAX : (uint64_t)a.sparse.indices.byteOffset;
            o->sparse_indices_type = a.sparse.indices.componentType;
            o->sparse_values_view = a.sparse.values.bufferView;
            o->sparse_values_offset = a.sparse.values.byteOffset < 0 ? UINT64_MAX : (uint64_t)a.sparse.values.byteOffset;
        }
    }

    d->mesh_count = (uint32_t)m.meshes.size();
    d->meshes = arena_array<mk_gltf_mesh>(arena, m.meshes.size());
    for (size_t i = 0; i < m.meshes.size(); ++i) {
        const tinygltf::Mesh &src = m.meshes[i];
        mk_gltf_mesh *o = &d->meshes[i];
        o->name = arena_str(arena, src.name);
        o->weight_count = (uint32_t)src.weights.size();
        o->weights = arena_array<double>(arena, src.weights.size());
        for (size_t k = 0; k < src.weights.size(); ++k) o->weights[k] = src.weights[k];
        copy_target_names(arena, src.extras, &o->target_name_count, &o->target_names);
        o->primitive_count = (uint32_t)src.primitives.size();
        o->primitives = arena_array<mk_gltf_primitive>(arena, src.primitives.size());
        for (size_t p = 0; p < src.primitives.size(); ++p) {
            const tinygltf::Primitive &sp = src.primitives[p];
            mk_gltf_primitive *op = &o->primitives[p];
            op->mode = sp.mode < 0 ? TINYGLTF_MODE_TRIANGLES : sp.mode;
            op->indices = sp.indices;
            auto hidden = impl->hidden_indices.find(std::make_pair((int)i, (int)p));
            if (hidden != impl->hidden_indices.end()) op->indices = hidden->second;
            copy_attributes(arena, sp.attributes, &op->attribute_count, &op->attributes);
            op->target_count = (uint32_t)sp.targets.size();
            op->targets = arena_array<mk_gltf_target>(arena, sp.targets.size());
            for (size_t t = 0; t < sp.targets.size(); ++t)
                copy_attributes(arena, sp.targets[t], &op->targets[t].attribute_count, &op->targets[t].attributes);
            copy_target_names(arena, sp.extras, &op->target_name_count, &op->target_names);
            auto draco = sp.extensions.find("KHR_draco_mesh_compression");
            if (draco != sp.extensions.end()) {
                std::string e = decode_draco(arena, m, sp, draco->second, impl->fallback_buffers, op);
                if (!e.empty()) {
                    *err = "mesh " + std::to_string(i) + " primitive " + std::to_string(p) +
                           ": KHR_draco_mesh_compression: " + e;
                    return;
                }
            }
        }
    }

    d->node_count = (uint32_t)m.nodes.size();
    d->nodes = arena_array<mk_gltf_node>(arena, m.nodes.size());
    for (size_t i = 0; i < m.nodes.size(); ++i) {
        const tinygltf::Node &n = m.nodes[i];
        mk_gltf_node *o = &d->nodes[i];
        o->name = arena_str(arena, n.name);
        o->mesh = n.mesh;
        o->child_count = (uint32_t)n.children.size();
        o->children = arena_array<int32_t>(arena, n.children.size());
        for (size_t k = 0; k < n.children.size(); ++k) o->children[k] = n.children[k];
        o->rotation[3] = 1.0;
        o->scale[0] = o->scale[1] = o->scale[2] = 1.0;
        if (n.matrix.size() == 16) {
            o->has_matrix = 1;
            for (int k = 0; k < 16; ++k) o->matrix[k] = n.matrix[k];
        } else if (!n.matrix.empty()) {
            *err = "node " + std::to_string(i) + ": matrix must have 16 numbers";
            return;
        }
        if (n.translation.size() == 3) for (int k = 0; k < 3; ++k) o->translation[k] = n.translation[k];
        else if (!n.translation.empty()) { *err = "node " + std::to_string(i) + ": translation must have 3 numbers"; return; }
        if (n.rotation.size() == 4) for (int k = 0; k < 4; ++k) o->rotation[k] = n.rotation[k];
        else if (!n.rotation.empty()) { *err = "node " + std::to_string(i) + ": rotation must have 4 numbers"; return; }
        if (n.scale.size() == 3) for (int k = 0; k < 3; ++k) o->scale[k] = n.scale[k];
        else if (!n.scale.empty()) { *err = "node " + std::to_string(i) + ": scale must have 3 numbers"; return; }
        o->weight_count = (uint32_t)n.weights.size();
        o->weights = arena_array<double>(arena, n.weights.size());
        for (size_t k = 0; k < n.weights.size(); ++k) o->weights[k] = n.weights[k];
    }

    d->animation_count = (uint32_t)m.animations.size();
    d->animations = arena_array<mk_gltf_animation>(arena, m.animations.size());
    for (size_t i = 0; i < m.animations.size(); ++i) {
        const tinygltf::Animation &a = m.animations[i];
        mk_gltf_animation *o = &d->animations[i];
        o->name = arena_str(arena, a.name);
        o->channel_count = (uint32_t)a.channels.size();
        o->channels = arena_array<mk_gltf_channel>(arena, a.channels.size());
        for (size_t k = 0; k < a.channels.size(); ++k) {
            o->channels[k].sampler = a.channels[k].sampler;
            o->channels[k].node = a.channels[k].target_node;
            o->channels[k].path = arena_str(arena, a.channels[k].target_path);
        }
        o->sampler_count = (uint32_t)a.samplers.size();
        o->samplers = arena_array<mk_gltf_sampler>(arena, a.samplers.size());
        for (size_t k = 0; k < a.samplers.size(); ++k) {
            const tinygltf::AnimationSampler &s = a.samplers[k];
            o->samplers[k].input = s.input;
            o->samplers[k].output = s.output;
            o->samplers[k].interpolation = s.interpolation == "LINEAR" ? MK_GLTF_LINEAR
                                         : s.interpolation == "STEP" ? MK_GLTF_STEP
                                         : s.interpolation == "CUBICSPLINE" ? MK_GLTF_CUBICSPLINE
                                         : MK_GLTF_INTERP_UNKNOWN;
        }
    }

    d->scene = m.defaultScene;
    int scene = m.defaultScene >= 0 ? m.defaultScene : (m.scenes.empty() ? -1 : 0);
    if (scene >= 0 && (size_t)scene < m.scenes.size()) {
        const std::vector<int> &roots = m.scenes[scene].nodes;
        d->scene_node_count = (uint32_t)roots.size();
        d->scene_nodes = arena_array<int32_t>(arena, roots.size());
        for (size_t k = 0; k < roots.size(); ++k) d->scene_nodes[k] = roots[k];
    } else if (scene >= 0) {
        *err = "default scene " + std::to_string(scene) + " out of range";
        return;
    }

    d->required_count = (uint32_t)m.extensionsRequired.size();
    d->extensions_required = arena_array<const char *>(arena, m.extensionsRequired.size());
    for (size_t k = 0; k < m.extensionsRequired.size(); ++k)
        d->extensions_required[k] = arena_str(arena, m.extensionsRequired[k]);
    d->generator = arena_str(arena, m.asset.generator);
}

// Trims tinygltf's multi-line messages to the first line that says something.
std::string first_line(const std::string &s)
{
    size_t start = s.find_first_not_of(" \n\r\t");
    if (start == std::string::npos) return "";
    size_t end = s.find('\n', start);
    return s.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

mk_result load(mk_arena *arena, const unsigned char *bytes, size_t size, int is_binary, const char *base_dir,
               uint64_t max_file_size, void (*file_read)(void *, const char *), void *file_read_user,
               mk_gltf_doc *out, mk_error *err)
{
    if (is_binary < 0) is_binary = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
    if (size > 0xffffffffu) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "glTF input larger than 4 GiB");

    std::unique_ptr<Impl> impl(new Impl());

    // Split the GLB ourselves so the JSON chunk can be patched (fallback buffers) and so the
    // error for a damaged container names the byte offset.
    std::string json_text;
    const unsigned char *bin = nullptr;
    uint32_t bin_size = 0;
    if (is_binary) {
        if (size < 20) return mk_error_set(err, MK_ERROR_TRUNCATED, size, "GLB shorter than its 20-byte header");
        if (std::memcmp(bytes, "glTF", 4) != 0) return mk_error_set(err, MK_ERROR_PARSE, 0, "GLB magic 'glTF' missing");
        if (rd32(bytes + 4) != 2) return mk_error_set(err, MK_ERROR_PARSE, 4, "GLB version %u, expected 2", rd32(bytes + 4));
        uint32_t total = rd32(bytes + 8);
        if (total > size) return mk_error_set(err, MK_ERROR_TRUNCATED, size, "GLB declares %u bytes, file has %zu", total, size);
        if (total < 20) return mk_error_set(err, MK_ERROR_PARSE, 8, "GLB length %u too small", total);
        uint32_t jlen = rd32(bytes + 12);
        if (rd32(bytes + 16) != 0x4E4F534Au) return mk_error_set(err, MK_ERROR_PARSE, 16, "GLB first chunk is not JSON");
        if (jlen > total - 20) return mk_error_set(err, MK_ERROR_TRUNCATED, 12, "GLB JSON chunk of %u bytes exceeds the file", jlen);
        json_text.assign(reinterpret_cast<const char *>(bytes + 20), jlen);
        uint64_t pos = 20 + (uint64_t)jlen;
        if (pos + 8 <= total) {
            uint32_t clen = rd32(bytes + pos), ctype = rd32(bytes + pos + 4);
            if (ctype == 0x004E4942u) {
                if (clen > total - pos - 8) return mk_error_set(err, MK_ERROR_TRUNCATED, pos, "GLB BIN chunk of %u bytes exceeds the file", clen);
                bin = bytes + pos + 8;
                bin_size = clen;
            }
        }
    } else {
        json_text.assign(reinterpret_cast<const char *>(bytes), size);
    }

    const size_t max_depth = 64;
    if (json_depth(json_text) > max_depth)
        return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "glTF JSON nests deeper than %zu levels", max_depth);
    nlohmann::json j = nlohmann::json::parse(json_text, nullptr, false);
    if (j.is_discarded()) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF JSON is malformed");
    if (!j.is_object()) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF JSON is not an object");
    bool patched = patch_fallback_buffers(j, impl->fallback_buffers);
    patched |= hide_viewless_indices(j, impl->hidden_indices);
    if (patched) json_text = j.dump();

    std::string glb;
    if (is_binary) {
        // Rebuild a GLB with the (possibly patched) JSON; chunks padded to 4 bytes.
        while (json_text.size() % 4) json_text.push_back(' ');
        uint64_t total = 12 + 8 + json_text.size() + (bin ? 8 + ((uint64_t)bin_size + 3) / 4 * 4 : 0);
        if (total > 0xffffffffu) return mk_error_set(err, MK_ERROR_LIMIT, UINT64_MAX, "GLB larger than 4 GiB");
        glb.reserve(total);
        glb.append("glTF");
        wr32(glb, 2);
        wr32(glb, (uint32_t)total);
        wr32(glb, (uint32_t)json_text.size());
        wr32(glb, 0x4E4F534Au);
        glb.append(json_text);
        if (bin) {
            wr32(glb, (bin_size + 3) / 4 * 4);
            wr32(glb, 0x004E4942u);
            glb.append(reinterpret_cast<const char *>(bin), bin_size);
            while (glb.size() % 4) glb.push_back('\0');
        }
    }

    FsContext fsctx;
    fsctx.allow_files = base_dir != nullptr;
    fsctx.base_dir = base_dir ? base_dir : "";
    const std::string marker = kBaseMarker;
    fsctx.max_size = max_file_size;
    fsctx.file_read = file_read;
    fsctx.file_read_user = file_read_user;
    tinygltf::FsCallbacks fs;
    fs.FileExists = fs_exists;
    fs.ExpandFilePath = fs_expand;
    fs.ReadWholeFile = fs_read;
    fs.WriteWholeFile = fs_write;
    fs.user_data = &fsctx;

    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(dummy_image_loader, nullptr);
    std::string terr, twarn;
    bool ok = is_binary
        ? loader.LoadBinaryFromMemory(&impl->model, &terr, &twarn, reinterpret_cast<const unsigned char *>(glb.data()),
                                      (unsigned int)glb.size(), marker)
        : loader.LoadASCIIFromString(&impl->model, &terr, &twarn, json_text.data(), (unsigned int)json_text.size(),
                                     marker);
    if (!ok) {
        // Our own account of an external file says which URI and which path; tinygltf's only
        // says "File not found".
        if (fsctx.failure_code != MK_OK)
            return mk_error_set(err, fsctx.failure_code, UINT64_MAX, "glTF %s", fsctx.failure.c_str());
        std::string msg = first_line(terr);
        if (msg.empty()) msg = "tinygltf refused the document";
        // tinygltf names external files by the path it built ("File size mismatch : <marker>/x.bin"):
        // show the real one.
        std::string dir = fsctx.base_dir;
        if (!dir.empty() && dir.back() != '/') dir += '/';
        for (size_t at = 0; (at = msg.find(marker + "/", at)) != std::string::npos; at += dir.size())
            msg.replace(at, marker.size() + 1, dir);
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF: %s", msg.c_str());
    }

    std::string cerr;
    convert(arena, impl.get(), out, &cerr);
    if (!cerr.empty()) return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF: %s", cerr.c_str());
    out->impl = impl.release();
    return MK_OK;
}

} // namespace

extern "C" mk_result mk_gltf_doc_load(mk_arena *arena, const void *data, size_t size, int is_binary,
                                      const char *base_dir, uint64_t max_file_size,
                                      void (*file_read)(void *user, const char *path), void *file_read_user,
                                      mk_gltf_doc *out, mk_error *err)
{
    if (!arena || !out || (!data && size)) return mk_error_set(err, MK_ERROR_INVALID_ARGUMENT, UINT64_MAX, "glTF: invalid argument");
    std::memset(out, 0, sizeof *out);
    try {
        mk_result r = load(arena, static_cast<const unsigned char *>(data), size, is_binary, base_dir,
                           max_file_size, file_read, file_read_user, out, err);
        if (r != MK_OK) std::memset(out, 0, sizeof *out);
        return r;
    } catch (const std::bad_alloc &) {
        std::memset(out, 0, sizeof *out);
        return mk_error_oom(err, "glTF document");
    } catch (const std::exception &e) {
        std::memset(out, 0, sizeof *out);
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF: %s", e.what());
    } catch (...) {
        std::memset(out, 0, sizeof *out);
        return mk_error_set(err, MK_ERROR_PARSE, UINT64_MAX, "glTF: parser failed");
    }
}

extern "C" void mk_gltf_doc_free(mk_gltf_doc *doc)
{
    if (!doc) return;
    delete static_cast<Impl *>(doc->impl);
    doc->impl = nullptr;
}
