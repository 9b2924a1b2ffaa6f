/* SPDX-License-Identifier: MIT */
/* Offline core: deterministic writer, raw -> blob -> raw round trip, quantization within the
 * tolerance (outlier blocks stored as float), raw validation errors, failing allocation K for every K,
 * atomic file writes. */

#include <stdlib.h>
#include <unistd.h>
#include "check.h"
#include "fixtures.h"

/* The same model gives the same bytes, whatever the thread count (targets are quantized and
 * laid out on worker threads), and so does the consuming writer (morphkit import's), which
 * leaves the targets empty and reports the same. */
static void test_deterministic(void)
{
    static const char *const runs[] = { "1 thread", "1 thread", "5 threads", "consuming, 1 thread", "consuming, 5 threads" };
    for (int p = 0; p < 2; p++)
        for (int fixture = 0; fixture < 3; fixture++) {
            mk_raw_asset raw[5];
            void *blob[5];
            size_t size[5];
            mk_write_report report[5];
            for (int k = 0; k < 5; k++) {
                mk_raw_init(&raw[k], NULL);
                if (fixture == 0) {
                    fixture_line(&raw[k], 700, 9, 2);
                    raw[k].channels[4].targets[0].positions[3 * 100] = 1e4f;   /* an outlier block: float */
                }
                else if (fixture == 1) fixture_rich(&raw[k]);
                else fixture_wavy_grid(&raw[k], 40, 17);
                mk_write_options wo = { .precision = (mk_precision)p, .threads = k == 2 || k == 4 ? 5u : 1u };
                mk_error err;
                if (k < 3) {
                    CHECK(mk_write_blob(&raw[k], &wo, &raw[k].arena, &blob[k], &size[k], &report[k], &err) == MK_OK);
                    continue;
                }
                CHECK(mk_write_blob_consuming(&raw[k], &wo, &blob[k], &size[k], &report[k], &err) == MK_OK);
                for (uint32_t c = 0; c < raw[k].channel_count; c++)
                    for (uint32_t t = 0; t < raw[k].channels[c].target_count; t++) {
                        const mk_raw_target *tg = &raw[k].channels[c].targets[t];
                        CHECK(tg->count == 0 && !tg->indices && !tg->positions && !tg->normals && !tg->tangents);
                    }
            }
            if (fixture == 0 && p == MK_PRECISION_Q16) CHECK_EQ_INT(report[0].float_entries, 1);
            for (int k = 1; k < 5; k++) {
                CHECK_MSG(size[0] == size[k] && memcmp(blob[0], blob[k], size[0]) == 0,
                          "fixture %d, precision %d: run %d (%s) differs", fixture, p, k, runs[k]);
                CHECK_MSG(memcmp(&report[0], &report[k], sizeof report[0]) == 0,
                          "fixture %d, precision %d: run %d (%s) reports otherwise", fixture, p, k, runs[k]);
            }
            for (int k = 0; k < 5; k++) mk_raw_free(&raw[k]);
        }
}

static void test_round_trip_float(void)
{
    mk_raw_asset raw, back;
    mk_raw_init(&raw, NULL);
    mk_raw_init(&back, NULL);
    fixture_basic(&raw);
    size_t size, size2;
    void *blob = fixture_blob(&raw, MK_PRECISION_FLOAT, &raw.arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    CHECK_EQ_INT(back.mesh_count, 2);
    CHECK_EQ_INT(back.channel_count, 5);
    CHECK(!strcmp(back.channels[1].name, "negative"));
    CHECK_NEAR(back.channels[1].targets[0].full_weight, -1, 0);
    CHECK_EQ_INT(back.channels[4].targets[0].count, 3);
    CHECK_EQ_INT(back.clips[0].tracks[0].key_count, 2);
    /* Writing the read-back model again gives the same bytes. */
    void *blob2 = fixture_blob(&back, MK_PRECISION_FLOAT, &back.arena, &size2);
    CHECK(size == size2 && memcmp(blob, blob2, size) == 0);
    mk_raw_free(&raw);
    mk_raw_free(&back);
}

static void test_quantization_tolerance(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 300, 4, 1);
    /* One target with a huge delta next to tiny ones: at the tolerance's step (0.001 / (0.5 +
     * 2^-8)) its block (block 0 of 5) spans 2^19 steps, more than 16 bits, so that entry is
     * float32 and the rest of the target packed. */
    raw.channels[3].targets[0].positions[1] = 1000.0f;
    mk_write_options o = { .precision = MK_PRECISION_Q16, .tolerance = 0.001f };
    void *blob;
    size_t size;
    mk_write_report rep;
    mk_error err;
    CHECK(mk_write_blob(&raw, &o, &raw.arena, &blob, &size, &rep, &err) == MK_OK);
    CHECK_EQ_INT(rep.float_targets, 0);
    CHECK_EQ_INT(rep.float_entries, 1);        /* 1000 / 65534 > 0.001: that block is float */
    CHECK_EQ_INT(rep.quantized_targets, 4);
    CHECK(rep.max_position_error <= 0.001);
    /* Read back: every delta within the reported error. */
    mk_asset a;
    mk_raw_asset back;
    mk_raw_init(&back, NULL);
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    double worst = 0;
    for (uint32_t c = 0; c < raw.channel_count; c++) {
        const mk_raw_target *t = &raw.channels[c].targets[0], *u = &back.channels[c].targets[0];
        /* Read-back drops vertices whose quantized delta is all zero; match by index. */
        uint32_t k = 0;
        for (uint32_t j = 0; j < t->count; j++) {
            while (k < u->count && u->indices[k] < t->indices[j]) k++;
            for (int d = 0; d < 3; d++) {
                double got = (k < u->count && u->indices[k] == t->indices[j]) ? u->positions[3 * k + (uint32_t)d] : 0;
                double e = fabs(got - t->positions[3 * j + (uint32_t)d]);
                worst = e > worst ? e : worst;
            }
        }
    }
    CHECK_MSG(worst <= rep.max_position_error + 1e-9, "worst %g > reported %g", worst, rep.max_position_error);
    /* A tolerance below the worst error: the step follows the tolerance (format v5 has one step
     * per attribute and mesh, where v4 scaled int16 to each target's largest value and needed
     * float or offset blocks to go finer), so the same blocks stay packed, at a smaller step,
     * and the error stays within the new tolerance. */
    const double before = rep.max_position_error;
    mk_target_info ti;
    CHECK(mk_target_get(&a, 3, 0, &ti));
    const float before_step = ti.position_scale;
    o.tolerance = (float)(0.75 * before);
    CHECK(before > 0 && mk_write_blob(&raw, &o, &raw.arena, &blob, &size, &rep, &err) == MK_OK);
    CHECK_EQ_INT(rep.float_entries, 1);
    CHECK_EQ_INT(rep.float_targets, 0);
    CHECK_EQ_INT(rep.wide_entries, 0);
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK && mk_target_get(&a, 3, 0, &ti));
    CHECK_MSG(ti.position_scale > 0 && ti.position_scale < 0.76f * before_step, "step %g at tolerance %g, %g before",
              (double)ti.position_scale, (double)o.tolerance, (double)before_step);
    CHECK_MSG(rep.max_position_error <= o.tolerance, "a quantized target errs by %g, over the tolerance %g",
              rep.max_position_error, (double)o.tolerance);
    /* Block 1 of target 2 moved 200 units along x: 10^5 steps, beyond the int16 offsets of
     * the entry's head, with a spread of a few dozen steps: one WIDE entry (int32 position
     * offsets in its data), still within the tolerance when read back. */
    mk_raw_target *t2 = &raw.channels[2].targets[0];
    for (uint32_t j = 0; j < t2->count; j++)
        if (t2->indices[j] / 64 == 1) t2->positions[3 * j] += 200.0f;
    CHECK(mk_write_blob(&raw, &o, &raw.arena, &blob, &size, &rep, &err) == MK_OK);
    CHECK_EQ_INT(rep.wide_entries, 1);
    CHECK_EQ_INT(rep.float_entries, 1);
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK_EQ_INT(mk_mesh_wide_entries(&a, 0), 1);
    CHECK_MSG(rep.max_position_error <= o.tolerance, "error %g with a WIDE entry, tolerance %g", rep.max_position_error,
              (double)o.tolerance);
    mk_raw_free(&back);
    mk_raw_init(&back, NULL);
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    const mk_raw_target *u2 = &back.channels[2].targets[0];
    CHECK_EQ_INT(u2->count, t2->count);
    worst = 0;
    for (uint32_t j = 0; j < u2->count && j < t2->count; j++)
        for (uint32_t d = 0; d < 3; d++) worst = fmax(worst, fabs((double)u2->positions[3 * j + d] - t2->positions[3 * j + d]));
    CHECK_MSG(worst <= rep.max_position_error + 1e-9, "WIDE read back %g, reported %g", worst, rep.max_position_error);
    mk_raw_free(&back);
    mk_raw_free(&raw);
}

static void test_validation_names_the_element(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_basic(&raw);
    mk_error err;
    CHECK(mk_raw_validate(&raw, &err) == MK_OK);
    raw.channels[0].targets[1].full_weight = 0.5f;          /* equal to the in-between */
    CHECK(mk_raw_validate(&raw, &err) == MK_ERROR_CORRUPT);
    CHECK(strstr(err.message, "channel 0 'progressive' target 1") != NULL);
    raw.channels[0].targets[1].full_weight = 1.0f;
    raw.channels[4].targets[0].indices[2] = 7;
    CHECK(mk_raw_validate(&raw, &err) == MK_ERROR_CORRUPT);
    CHECK(strstr(err.message, "index 7") != NULL);
    raw.channels[4].targets[0].indices[2] = 2;
    raw.meshes[0].positions[5] = NAN;
    CHECK(mk_raw_validate(&raw, &err) == MK_ERROR_NOT_FINITE);
    raw.meshes[0].positions[5] = 0;
    raw.clips[0].tracks[0].keys[1].time = 0;
    CHECK(mk_raw_validate(&raw, &err) == MK_ERROR_CORRUPT);
    CHECK(strstr(err.message, "clip 0 track 0 key 1") != NULL);
    /* The writer refuses what validation refuses, and writes nothing. */
    void *blob = NULL;
    size_t size = 0;
    CHECK(mk_write_blob(&raw, NULL, &raw.arena, &blob, &size, NULL, &err) == MK_ERROR_CORRUPT);
    CHECK(blob == NULL);
    mk_raw_free(&raw);
}

static void test_group_channels(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_basic(&raw);
    /* Swap channel 0 (mesh 0) and 4 (mesh 1): the track of channel 4 must follow it. */
    mk_raw_channel tmp = raw.channels[0];
    raw.channels[0] = raw.channels[4];
    raw.channels[4] = tmp;
    raw.clips[0].tracks[0].channel = 4;
    raw.clips[0].tracks[1].channel = 0;
    mk_error err;
    CHECK(mk_raw_group_channels(&raw, &err) == MK_OK);
    CHECK(!strcmp(raw.channels[4].name, "lift"));
    CHECK(!strcmp(raw.channels[3].name, "progressive"));
    CHECK_EQ_INT(raw.clips[0].tracks[0].channel, 3);
    CHECK_EQ_INT(raw.clips[0].tracks[1].channel, 4);
    CHECK(mk_raw_validate(&raw, &err) == MK_OK);
    mk_raw_free(&raw);
}

/* Fail allocation K for every K: each failure is a clean MK_ERROR_OUT_OF_MEMORY, and all
 * memory is returned (the arena counts live bytes; LeakSanitizer checks under ASan). */
static void test_fail_allocation_k(void)
{
    mk_raw_asset src;
    mk_raw_init(&src, NULL);
    fixture_basic(&src);
    size_t size;
    void *blob = fixture_blob(&src, MK_PRECISION_Q16, &src.arena, &size);
    mk_asset a;
    mk_error err;
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    int succeeded = 0, failures = 0;
    for (uint64_t k = 1; k < 10000 && !succeeded; k++) {
        mk_allocator al = { .fail_after = k };
        mk_raw_asset raw;
        mk_raw_init(&raw, &al);
        mk_result r = mk_read_blob(&a, &raw, &err);
        void *out = NULL;
        size_t out_size;
        if (r == MK_OK) r = mk_raw_compute_target_normals(&raw, 0, 1, 0, &err);
        if (r == MK_OK) r = mk_write_blob(&raw, NULL, &raw.arena, &out, &out_size, NULL, &err);
        if (r == MK_OK) succeeded = 1;
        else {
            failures++;
            CHECK_MSG(r == MK_ERROR_OUT_OF_MEMORY, "K=%llu: %s", (unsigned long long)k, err.message);
        }
        mk_raw_free(&raw);
        CHECK_EQ_INT(raw.arena.bytes_live, 0);
    }
    CHECK(succeeded);
    printf("  %d allocation failures injected, all clean\n", failures);
    mk_raw_free(&src);
}

/* The memory limit of the allocator is honoured: a writer that would need more than the
 * limit fails with out-of-memory, and a generous limit succeeds. */
static void test_memory_limit(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 5000, 8, 1);
    mk_allocator tight = { .memory_limit = 64 * 1024 };
    mk_arena arena;
    mk_arena_init(&arena, &tight);
    void *blob;
    size_t size;
    mk_error err;
    CHECK(mk_write_blob(&raw, NULL, &arena, &blob, &size, NULL, &err) == MK_ERROR_OUT_OF_MEMORY);
    CHECK(arena.bytes_peak <= tight.memory_limit);
    mk_arena_free_all(&arena);
    mk_allocator roomy = { .memory_limit = 64 * 1024 * 1024 };
    mk_arena_init(&arena, &roomy);
    CHECK(mk_write_blob(&raw, NULL, &arena, &blob, &size, NULL, &err) == MK_OK);
    printf("  peak %zu bytes for a %zu-byte blob\n", arena.bytes_peak, size);
    mk_arena_free_all(&arena);
    mk_raw_free(&raw);
}

static void test_atomic_write(void)
{
    char dir[] = "/tmp/mk_atomic_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256], bad[256];
    snprintf(path, sizeof path, "%s/out.morph", dir);
    snprintf(bad, sizeof bad, "%s/missing/out.morph", dir);
    mk_error err;
    CHECK(mk_write_file(path, "abc", 3, &err) == MK_OK);
    CHECK(mk_write_file(path, "defg", 4, &err) == MK_OK);
    size_t n;
    unsigned char *got = check_read_file(path, &n);
    CHECK(got && n == 4 && !memcmp(got, "defg", 4));
    free(got);
    CHECK(mk_write_file(bad, "x", 1, &err) == MK_ERROR_IO);
    CHECK(strstr(err.message, "missing") != NULL);
    /* No temporary file left behind. */
    char cmd[512];
    snprintf(cmd, sizeof cmd, "test $(ls -A %s | wc -l) -eq 1", dir);
    CHECK(system(cmd) == 0);
    remove(path);
    rmdir(dir);
}

/* Normal and tangent deltas are quantized too, at the step of the normal tolerance (default
 * MK_DEFAULT_NORMAL_TOLERANCE; v4 scaled int16 to each target's range and erred below 3.1e-5):
 * the report gives their error, within that tolerance, and read-back stays within it. */
static void test_normal_tangent_error_reported(void)
{
    mk_raw_asset raw;
    mk_raw_init(&raw, NULL);
    fixture_line(&raw, 200, 2, 1);
    mk_raw_mesh *m = &raw.meshes[0];
    m->tangents = mk_arena_array(&raw.arena, 4 * (size_t)m->vertex_count, sizeof(float));
    for (uint32_t v = 0; v < m->vertex_count; v++) { m->tangents[4 * v] = 1; m->tangents[4 * v + 3] = 1; }
    mk_raw_target *t = &raw.channels[0].targets[0];
    t->tangents = mk_arena_array(&raw.arena, 3 * (size_t)t->count, sizeof(float));
    for (uint32_t j = 0; j < t->count; j++) {
        t->tangents[3 * j] = 0.8f * sinf(0.37f * (float)j) - 0.5f;
        t->tangents[3 * j + 1] = 0.3f * cosf(0.11f * (float)j);
    }
    mk_write_options o = { .precision = MK_PRECISION_Q16 };
    void *blob;
    size_t size;
    mk_write_report rep;
    mk_error err;
    CHECK(mk_write_blob(&raw, &o, &raw.arena, &blob, &size, &rep, &err) == MK_OK);
    CHECK_MSG(rep.max_tangent_error > 0 && rep.max_tangent_error <= MK_DEFAULT_NORMAL_TOLERANCE, "tangent error %g",
              rep.max_tangent_error);
    CHECK_MSG(rep.max_normal_error > 0 && rep.max_normal_error <= MK_DEFAULT_NORMAL_TOLERANCE, "normal error %g",
              rep.max_normal_error);
    mk_asset a;
    mk_raw_asset back;
    mk_raw_init(&back, NULL);
    CHECK(mk_asset_open(blob, size, &a, &err) == MK_OK);
    CHECK(mk_read_blob(&a, &back, &err) == MK_OK);
    const mk_raw_target *u = &back.channels[0].targets[0];
    double worst = 0;
    CHECK(u->tangents != NULL && u->count == t->count);
    for (uint32_t j = 0; u->tangents && u->count == t->count && j < 3 * t->count; j++) {
        double e = fabs((double)u->tangents[j] - t->tangents[j]);
        worst = e > worst ? e : worst;
    }
    CHECK_MSG(worst > 0 && worst <= rep.max_tangent_error + 1e-9, "worst %g, reported %g", worst, rep.max_tangent_error);
    mk_raw_free(&back);
    mk_raw_free(&raw);
}

static void test_path_has_extension(void)
{
    CHECK(mk_path_has_extension("a/b.glb", ".glb"));
    CHECK(mk_path_has_extension("A/B.GLB", ".glb"));
    CHECK(mk_path_has_extension("x.Obj", ".obj"));
    CHECK(!mk_path_has_extension("x.obj.json", ".obj"));
    CHECK(!mk_path_has_extension("glb", ".glb"));
    CHECK(!mk_path_has_extension("", ".fbx"));
    CHECK(mk_path_has_extension(".fbx", ".fbx"));
}

CHECK_MAIN(CASE(test_deterministic), CASE(test_round_trip_float), CASE(test_quantization_tolerance),
           CASE(test_validation_names_the_element), CASE(test_group_channels), CASE(test_fail_allocation_k),
           CASE(test_memory_limit), CASE(test_atomic_write), CASE(test_normal_tangent_error_reported),
           CASE(test_path_has_extension))
