/* SPDX-License-Identifier: MIT */
/* The .morph blob layout, version 4 (docs/format.md is the prose description).
 *
 * Little-endian. Every record and array starts at a multiple of 16 bytes from the blob start.
 * Offsets are absolute byte offsets from the blob start. Strings are offsets into the STRINGS
 * section (NUL-terminated; the section ends with a NUL).
 *
 *   header (64 B) | section table (section_count x 32 B) | sections ...
 *
 * Shared by the runtime (reader) and the offline writer; nothing here allocates.
 */
#ifndef MK_FORMAT_H
#define MK_FORMAT_H

#include <stdint.h>

#define MK_MAGIC "MORPHKIT"
#define MK_BLOCK_SIZE 64u          /* vertices per block: one uint64 mask bit per vertex */
#define MK_ALIGN 16u
#define MK_MAX_VERTICES (UINT32_MAX - (MK_BLOCK_SIZE - 1))   /* per mesh: 2^32 - 64 */

enum {
    MK_SECTION_STRINGS = 1,        /* char[] */
    MK_SECTION_MESHES = 2,         /* mk_blob_mesh[] */
    MK_SECTION_CHANNELS = 3,       /* mk_blob_channel[] */
    MK_SECTION_TARGETS = 4,        /* mk_blob_target[] */
    MK_SECTION_CLIPS = 5,          /* mk_blob_clip[] */
    MK_SECTION_TRACKS = 6,         /* mk_blob_track[] */
    MK_SECTION_KEYS = 7,           /* mk_key[] */
    MK_SECTION_DATA = 8,           /* bulk arrays referenced by meshes */
    MK_SECTION_KIND_COUNT = 9
};

typedef struct mk_blob_header {
    char magic[8];                 /* "MORPHKIT" */
    uint32_t version;              /* MK_FORMAT_VERSION */
    uint32_t header_size;          /* 64 */
    uint64_t file_size;            /* whole blob in bytes */
    uint64_t checksum;             /* mk_checksum of bytes [32, file_size) */
    uint32_t section_count;
    uint32_t flags;                /* zero */
    uint32_t reserved[6];          /* zero */
} mk_blob_header;

typedef struct mk_blob_section {
    uint32_t kind;                 /* MK_SECTION_* (each at most once) */
    uint32_t element_size;         /* bytes per element (1 for STRINGS and DATA) */
    uint64_t count;                /* elements */
    uint64_t offset;               /* absolute, 16-aligned */
    uint64_t size;                 /* bytes = count * element_size */
} mk_blob_section;

enum {
    MK_MESH_HAS_NORMALS = 1u,
    MK_MESH_HAS_TANGENTS = 2u
};

typedef struct mk_blob_mesh {
    uint32_t name;                 /* string */
    uint32_t vertex_count;
    uint32_t control_point_count;
    uint32_t triangle_count;
    uint32_t first_channel, channel_count;   /* contiguous range of the asset's channels */
    uint32_t first_target, target_count;     /* contiguous range of the asset's targets */
    uint32_t stacking;             /* MK_STACKING_ADDITIVE or MK_STACKING_SEQUENTIAL */
    uint32_t flags;                /* MK_MESH_HAS_* */
    int32_t gltf_node, gltf_mesh, gltf_primitive;
    uint32_t block_count;          /* ceil(vertex_count / 64) */
    uint32_t reserved[2];
    float world[16];               /* column-major */
    uint64_t positions;            /* float[3 * vertex_count] */
    uint64_t normals;              /* float[3 * vertex_count] or 0 */
    uint64_t tangents;             /* float[4 * vertex_count] or 0 */
    uint64_t triangles;            /* uint32[3 * triangle_count] or 0 */
    uint64_t control_points;       /* uint32[vertex_count] */
    uint64_t block_entries;        /* uint32[block_count + 1]: first entry of each block */
    uint64_t entries;              /* mk_blob_entry[entry_count] */
    uint64_t entry_count;
    uint64_t target_data;          /* start of this mesh's delta data */
    uint64_t target_data_size;     /* bytes */
} mk_blob_mesh;                    /* 208 bytes */

typedef struct mk_blob_channel {
    uint32_t name, origin;         /* strings */
    uint32_t mesh;
    uint32_t first_target;         /* asset target index; targets in increasing full weight */
    uint32_t target_count;         /* >= 1 */
    float default_weight;
    uint32_t reserved[2];
} mk_blob_channel;                 /* 32 bytes */

enum {
    MK_TARGET_QUANTIZED = 1u,      /* has int16 entries: components times the per-attribute scale */
    MK_TARGET_HAS_NORMALS = 2u,
    MK_TARGET_HAS_TANGENTS = 4u
};

typedef struct mk_blob_target {
    uint32_t name;                 /* string */
    uint32_t channel;              /* asset channel index */
    float full_weight;             /* nonzero; strictly increasing within the channel */
    uint32_t flags;                /* MK_TARGET_* */
    float position_scale;          /* dequantization step (quantized targets), else 0 */
    float normal_scale;
    float tangent_scale;
    uint32_t moved_vertices;
} mk_blob_target;                  /* 32 bytes */

/* One target's data for one block of 64 vertices. Entries of a block are sorted by target
 * (mesh-local index), so a channel's targets are adjacent. The data holds m = popcount(mask)
 * xyz triples in mask-bit order, interleaved like the outputs: the position deltas
 * x0 y0 z0 x1 y1 z1 ..., then the normal deltas if the target has normals, then the tangent
 * deltas (xyz) if it has tangents; float32 when the entry has MK_ENTRY_FLOAT, else int16 times
 * the target's scales (only a quantized target has int16 entries; a float target's entries all
 * have the flag), after the position offset of an MK_ENTRY_OFFSET entry. A run of consecutive
 * mask bits is one contiguous span of data and output. The mask may cover vertices the target
 * does not move: their deltas are zeros, except in an MK_ENTRY_OFFSET entry, whose every
 * covered vertex moves by offset + int16 x scale (the writer covers only moved vertices there). */
#define MK_ENTRY_TARGET_MASK 0x00FFFFFFu   /* target_and_flags: the mesh-local target index */
#define MK_MAX_MESH_TARGETS (MK_ENTRY_TARGET_MASK + 1u)   /* targets per mesh: 2^24 */
#define MK_ENTRY_FLOAT 0x80000000u       /* target_and_flags: the entry's data is float32 */
/* target_and_flags: an int16 entry whose position deltas are offset + int16 x scale; its data
 * starts with the offset (MK_ENTRY_OFFSET_BYTES: f32 x, y, z, then 4 zero bytes). Lets a block
 * of large deltas with a narrow spread stay int16 within the tolerance. */
#define MK_ENTRY_OFFSET 0x40000000u
#define MK_ENTRY_OFFSET_BYTES 16u
#define MK_ENTRY_FLAGS_KNOWN (MK_ENTRY_FLOAT | MK_ENTRY_OFFSET)

typedef struct mk_blob_entry {
    uint32_t target_and_flags;     /* mesh-local target index (low 24 bits) | MK_ENTRY_* */
    uint32_t data;                 /* offset from mesh.target_data, in 16-byte units */
    uint64_t mask;                 /* bit i: vertex block*64 + i has data */
} mk_blob_entry;                   /* 16 bytes */

typedef struct mk_blob_clip {
    uint32_t name;
    uint32_t first_track, track_count;
    float start, duration;         /* seconds */
    uint32_t reserved[3];
} mk_blob_clip;                    /* 32 bytes */

typedef struct mk_blob_track {
    uint32_t channel;              /* asset channel index */
    uint32_t first_key, key_count; /* key_count >= 1; times strictly increasing */
    uint32_t reserved;
} mk_blob_track;                   /* 16 bytes */

/* Smallest |full weight| and smallest gap between a channel's key points (including the
 * implicit 0): keeps span parameters finite for any reasonable weight. */
/* MK_MIN_FULL_WEIGHT_GAP is public (morphkit.h). */

/* Bit helpers with a portable fallback (the runtime must build with any C11 compiler). */
static inline uint32_t mk_popcount64(uint64_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return (uint32_t)__builtin_popcountll(x);
#else
    uint32_t n = 0;
    while (x) { x &= x - 1; n++; }
    return n;
#endif
}

/* Index of the lowest set bit; x must be nonzero. */
static inline unsigned mk_ctz64(uint64_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctzll(x);
#else
    unsigned n = 0;
    while (!(x & 1)) { x >>= 1; n++; }
    return n;
#endif
}

/* 64-bit checksum (documented in docs/format.md). */
uint64_t mk_checksum(const void *data, uint64_t size);

static inline uint32_t mk_entry_target(const mk_blob_entry *e) { return e->target_and_flags & MK_ENTRY_TARGET_MASK; }
static inline int mk_entry_quantized(const mk_blob_entry *e) { return (e->target_and_flags & MK_ENTRY_FLOAT) == 0; }
static inline int mk_entry_has_offset(const mk_blob_entry *e) { return (e->target_and_flags & MK_ENTRY_OFFSET) != 0; }

/* The flags that size an entry's data: its target's attributes, MK_TARGET_QUANTIZED when the
 * entry holds int16 (quantized: mk_entry_quantized of a stored entry, or the writer's choice). */
static inline uint32_t mk_entry_flags(uint32_t target_flags, int quantized)
{
    return (target_flags & ~(uint32_t)MK_TARGET_QUANTIZED) | (quantized ? (uint32_t)MK_TARGET_QUANTIZED : 0u);
}

/* Bytes of one entry's data: m values per component, 3 components per attribute; flags as
 * mk_entry_flags gives them (MK_TARGET_QUANTIZED: int16, else float32). */
static inline uint64_t mk_entry_data_size(uint32_t flags, uint32_t m)
{
    uint64_t elem = (flags & MK_TARGET_QUANTIZED) ? 2u : 4u;
    uint64_t attributes = 1u + ((flags & MK_TARGET_HAS_NORMALS) ? 1u : 0u)
                        + ((flags & MK_TARGET_HAS_TANGENTS) ? 1u : 0u);
    return attributes * 3u * elem * m;
}

/* Bytes of one attribute (positions, normals or tangents) of a stored entry's data: its m
 * triples at the entry's own precision. */
static inline uint64_t mk_entry_attribute_bytes(const mk_blob_entry *e)
{
    return mk_entry_data_size(mk_entry_flags(0u, mk_entry_quantized(e)), mk_popcount64(e->mask));
}

/* Bytes of a stored entry's data (its offset, then its attributes) for its target's flags. */
static inline uint64_t mk_entry_bytes(const mk_blob_entry *e, uint32_t target_flags)
{
    return (mk_entry_has_offset(e) ? MK_ENTRY_OFFSET_BYTES : 0u) +
           mk_entry_data_size(mk_entry_flags(target_flags, mk_entry_quantized(e)), mk_popcount64(e->mask));
}

#endif
