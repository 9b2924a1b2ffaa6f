/* SPDX-License-Identifier: MIT */
/* The frame loop of the shell simulation (shell.h): per substep (shell_steps.c) prediction under
 * pressure, Gauss-Seidel sweeps over the energy constraints (XPBD, C = sqrt(2 W), compliance 1;
 * for hinges the signed root, shell_bending_steps)
 * and velocities from positions; per frame collision handling over the frame's motion and the
 * per-frame record. The sweeps (in the order of shell_order.c) and the collision tests run on a
 * team of threads in a way that gives the same result for any thread count, so a run is
 * reproducible bit for bit. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "shell.h"
#include "bake_util.h"
#include "mesh_groups.h"
#include "parallel.h"

typedef struct shell_state {
    const shell_mesh *m;
    const shell_params *p;
    uint32_t *aniso_tris;     /* triangles of the anisotropic region */
    uint32_t *aniso_idx;      /* their vertices, 3 per region triangle */
    uint32_t aniso_count;
    double *fibre;            /* 2 per region triangle */
    double *sign;             /* per region triangle: orientation against the neighbourhood */
    double *lambda;           /* per constraint: triangles, hinges, region triangles */
    shell_sweep_order tri_order, hinge_order;  /* the sweeps' order */
    mk_team *team;            /* threads for the sweeps' parts (NULL: the caller's only) */
    double *hinge_root;       /* per hinge: sqrt(kB scale) (shell_bending_steps) */
} shell_state;

/* XPBD projections of the energy constraints C = sqrt(2 W) of a batch of (triangle) elements (k
 * vertices each, sharing no vertex; element j has vertices idx[k e[j] ..], energy W[j], gradient
 * g[j] of W and multiplier lambda[e[j]]). grad C = g / C, so with C^2 = 2 W the step is
 * dl = (-C - alpha lambda) C^2 / (2 W alpha + sum_i w_i |g_i|^2) and each vertex moves by
 * w_i g_i dl / C = w_i g_i (-C - alpha lambda) C / (2 W alpha + sum): one division per element,
 * which does not wait for the square root. All steps are computed before any vertex moves,
 * which is the same as one element after the other because the elements share no vertex, and
 * lets their square roots and divisions overlap. */
static void project_batch(const shell_mesh *m, double *x, const uint32_t *idx, int k, const uint32_t *e, uint32_t size,
                          const double *W, double g[][12], double alpha, double *lambda)
{
    double step[SHELL_BATCH];
    for (uint32_t j = 0; j < size; j++) {
        const uint32_t *v = idx + (size_t)k * e[j];
        double sum = 0;
        for (int i = 0; i < k; i++) sum += m->inv_mass[v[i]] * vec3_dot(g[j] + 3 * i, g[j] + 3 * i);
        double den = 2 * W[j] * alpha + sum, C = sqrt(2 * W[j]), s = 0;
        if (W[j] > 1e-300 && den > 0) {
            double inv = 1 / den;
            s = (-C - alpha * lambda[e[j]]) * C * inv;
            lambda[e[j]] += s * C;
        }
        step[j] = s;
    }
    for (uint32_t j = 0; j < size; j++) {
        const uint32_t *v = idx + (size_t)k * e[j];
        for (int i = 0; i < k; i++) {
            double f = m->inv_mass[v[i]] * step[j];
            for (int c = 0; c < 3; c++) x[3 * (size_t)v[i] + c] += f * g[j][3 * i + c];
        }
    }
}

/* Projects the hinges of batches [first, last) of their sweep order (shell_bending_steps); adds
 * their energies to *energy in order. */
static void project_hinge_batches(const shell_state *s, double *x, double alpha, uint32_t first, uint32_t last,
                                  double *energy)
{
    const shell_mesh *m = s->m;
    const shell_sweep_order *o = &s->hinge_order;
    double *lambda = s->lambda + m->tri_count, sum = *energy;
    for (uint32_t b = first; b < last; b++) {
        const uint32_t *e = o->order + o->start[b];
        uint32_t size = o->start[b + 1] - o->start[b];
        const double *K[SHELL_BATCH], *xs[SHELL_BATCH][4];
        double w[SHELL_BATCH][4], root[SHELL_BATCH], rest[SHELL_BATCH], *lam[SHELL_BATCH], W[SHELL_BATCH], u[SHELL_BATCH][3];
        for (uint32_t j = 0; j < size; j++) {
            const uint32_t h = e[j], *v = m->hinges + 4 * (size_t)h;
            for (int i = 0; i < 4; i++) {
                xs[j][i] = x + 3 * (size_t)v[i];
                w[j][i] = m->inv_mass[v[i]];
            }
            K[j] = m->hinge_K + 4 * (size_t)h;
            root[j] = s->hinge_root[h];
            rest[j] = m->hinge_rest[h];
            lam[j] = &lambda[h];
        }
        shell_bending_steps(size, K, w, root, rest, alpha, xs, lam, W, u);
        for (uint32_t j = 0; j < size; j++) {
            sum += W[j];
            const uint32_t *v = m->hinges + 4 * (size_t)e[j];
            for (int i = 0; i < 4; i++) {
                double f = w[j][i] * K[j][i];
                for (int c = 0; c < 3; c++) x[3 * (size_t)v[i] + c] += f * u[j][c];
            }
        }
    }
    *energy = sum;
}

/* Evaluates (energy W, gradient) and, with alpha >= 0, projects the triangles (hinges = 0) or
 * hinges (hinges = 1) of batches [first, last) of their sweep order; adds their energies to *energy
 * in order. */
static void sweep_batches(const shell_state *s, double *x, double alpha, int hinges, uint32_t first, uint32_t last,
                          double *energy)
{
    const shell_mesh *m = s->m;
    const shell_params *p = s->p;
    const shell_sweep_order *o = hinges ? &s->hinge_order : &s->tri_order;
    const uint32_t *idx = hinges ? m->hinges : m->tris;
    const int k = hinges ? 4 : 3;
    if (hinges && alpha >= 0) {
        project_hinge_batches(s, x, alpha, first, last, energy);
        return;
    }
    double g[SHELL_BATCH][12], W[SHELL_BATCH], sum = *energy;  /* summed here: parts' sums share cache lines */
    for (uint32_t b = first; b < last; b++) {
        const uint32_t *e = o->order + o->start[b];
        uint32_t size = o->start[b + 1] - o->start[b];
        if (!hinges && p->material == SHELL_STVK) {
            const double *xs[SHELL_BATCH][3], *Dm[SHELL_BATCH];
            double area[SHELL_BATCH];
            for (uint32_t j = 0; j < size; j++) {
                const uint32_t t = e[j], *v = idx + 3 * (size_t)t;
                for (int i = 0; i < 3; i++) xs[j][i] = x + 3 * (size_t)v[i];
                Dm[j] = m->Dm_inv + 4 * (size_t)t;
                area[j] = m->area[t];
            }
            shell_stvk_batch(p->mu, p->lambda, size, xs, Dm, area, W, g);
        } else {
            for (uint32_t j = 0; j < size; j++) {
                const uint32_t *v = idx + (size_t)k * e[j];
                if (hinges) {   /* energies only: the projecting sweeps took project_hinge_batches */
                    const double *xs[4] = { x + 3 * (size_t)v[0], x + 3 * (size_t)v[1], x + 3 * (size_t)v[2],
                                            x + 3 * (size_t)v[3] };
                    W[j] = shell_bending_energy(m->hinge_K + 4 * (size_t)e[j], m->hinge_scale[e[j]], m->hinge_rest[e[j]],
                                                p->kB, xs, g[j]);
                } else {
                    uint32_t t = e[j];
                    W[j] = shell_membrane_energy(p->material, p->mu, p->lambda, m->Dm_inv + 4 * (size_t)t,
                                                 m->basis + 6 * (size_t)t, m->area[t], x + 3 * (size_t)v[0],
                                                 x + 3 * (size_t)v[1], x + 3 * (size_t)v[2], g[j]);
                }
            }
        }
        for (uint32_t j = 0; j < size; j++) sum += W[j];
        if (alpha >= 0) project_batch(m, x, idx, k, e, size, W, g, alpha, s->lambda);   /* triangles: hinges return above */
    }
    *energy = sum;
}

/* One part of a parallel sweep (shell_order.c): parts share no vertex. */
typedef struct sweep_job {
    const shell_state *s;
    double *x;
    double alpha;
    int hinges;
    uint32_t first_part;      /* the phase's */
    double energy[SHELL_PHASES_MAX * SHELL_PARTS_MAX];  /* per part */
} sweep_job;

static void sweep_part(void *user, uint32_t part, uint32_t worker)
{
    (void)worker;
    sweep_job *j = user;
    const shell_sweep_order *o = j->hinges ? &j->s->hinge_order : &j->s->tri_order;
    uint32_t q = j->first_part + part;
    sweep_batches(j->s, j->x, j->alpha, j->hinges, o->part_batch[q], o->part_batch[q + 1], &j->energy[q]);
}

/* Energies of the three kinds at positions x; with project_alpha >= 0 each element is also
 * projected right after it is evaluated (one Gauss-Seidel sweep). Triangles, then hinges, in
 * their sweep orders (shell_order.c): phase after phase, a phase's parts on the team's threads;
 * the result is the same for any thread count. Energies are summed per part, then in part order. */
static void sweep(const shell_state *s, double *x, double project_alpha, double energy[3])
{
    const shell_mesh *m = s->m;
    const shell_params *p = s->p;
    energy[0] = energy[1] = energy[2] = 0;
    for (int hinges = 0; hinges < 2; hinges++) {
        if (hinges && !(p->kB > 0)) break;
        const shell_sweep_order *o = hinges ? &s->hinge_order : &s->tri_order;
        sweep_job job = { .s = s, .x = x, .alpha = project_alpha, .hinges = hinges };
        for (uint32_t f = 0; f < o->phase_count; f++) {
            job.first_part = o->phase_part[f];
            mk_team_for(s->team, o->phase_part[f + 1] - o->phase_part[f], sweep_part, &job);
        }
        for (uint32_t q = 0; q < o->part_count; q++) energy[hinges] += job.energy[q];
    }
    for (uint32_t i = 0; i < s->aniso_count && p->aniso_mu > 0; i++) {
        uint32_t t = s->aniso_tris[i];
        double g[1][12], W[1];
        W[0] = shell_aniso_energy(p->aniso_energy, p->aniso_mu, s->sign[i], s->fibre + 2 * (size_t)i,
                                  m->Dm_inv + 4 * (size_t)t, m->area[t], x + 3 * (size_t)s->aniso_idx[3 * (size_t)i],
                                  x + 3 * (size_t)s->aniso_idx[3 * (size_t)i + 1], x + 3 * (size_t)s->aniso_idx[3 * (size_t)i + 2], g[0]);
        energy[2] += W[0];
        if (project_alpha >= 0)
            project_batch(m, x, s->aniso_idx, 3, &i, 1, W, g, project_alpha, s->lambda + m->tri_count + m->hinge_count);
    }
}

/* The region's triangles and their fibres: the direction projected into each rest triangle. */
static mk_result setup_region(shell_state *s, mk_arena *arena, mk_error *err)
{
    const shell_mesh *m = s->m;
    const shell_params *p = s->p;
    if (!p->aniso_region) return MK_OK;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *tri = m->tris + 3 * (size_t)t;
        if (p->aniso_region[tri[0]] && p->aniso_region[tri[1]] && p->aniso_region[tri[2]]) s->aniso_count++;
    }
    s->aniso_tris = mk_arena_array(arena, s->aniso_count + 1, sizeof(uint32_t));
    s->fibre = mk_arena_array(arena, 2 * (size_t)s->aniso_count + 2, sizeof(double));
    s->sign = mk_arena_array(arena, s->aniso_count + 1, sizeof(double));
    s->aniso_idx = mk_arena_array(arena, 3 * (size_t)s->aniso_count + 3, sizeof(uint32_t));
    if (!s->aniso_tris || !s->fibre || !s->sign || !s->aniso_idx) return mk_error_oom(err, "shell region");
    uint32_t k = 0;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *tri = m->tris + 3 * (size_t)t;
        if (!(p->aniso_region[tri[0]] && p->aniso_region[tri[1]] && p->aniso_region[tri[2]])) continue;
        const double *e1 = m->basis + 6 * (size_t)t, *e2 = e1 + 3;
        double a[2] = { vec3_dot(p->aniso_direction, e1), vec3_dot(p->aniso_direction, e2) };
        double l = sqrt(a[0] * a[0] + a[1] * a[1]);
        if (l < 1e-9) { a[0] = 1; a[1] = 0; l = 1; }  /* direction along the normal: the first rest axis */
        s->fibre[2 * (size_t)k] = a[0] / l;
        s->fibre[2 * (size_t)k + 1] = a[1] / l;
        s->sign[k] = 1;
        memcpy(s->aniso_idx + 3 * (size_t)k, tri, 3 * sizeof(uint32_t));
        s->aniso_tris[k++] = t;
    }
    return MK_OK;
}

/* sqrt(kB scale) per hinge, for shell_bending_steps. */
static mk_result setup_hinges(shell_state *s, mk_arena *arena, mk_error *err)
{
    const shell_mesh *m = s->m;
    s->hinge_root = mk_arena_array(arena, (size_t)m->hinge_count + 1, sizeof(double));
    if (!s->hinge_root) return mk_error_oom(err, "shell hinges");
    for (uint32_t h = 0; h < m->hinge_count; h++) s->hinge_root[h] = sqrt(s->p->kB * m->hinge_scale[h]);
    return MK_OK;
}

/* sign(I4) per region triangle: its current normal against the mean of its vertex normals. */
static void update_signs(shell_state *s, const double *x, const double *normals)
{
    const shell_mesh *m = s->m;
    for (uint32_t i = 0; i < s->aniso_count; i++) {
        const uint32_t *tri = m->tris + 3 * (size_t)s->aniso_tris[i];
        double n[3], ref[3] = { 0, 0, 0 };
        mk_triangle_normal(x + 3 * (size_t)tri[0], x + 3 * (size_t)tri[1], x + 3 * (size_t)tri[2], n);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) ref[c] += normals[3 * (size_t)tri[k] + c];
        s->sign[i] = vec3_dot(n, ref) < 0 ? -1 : 1;
    }
}

/* A substep's per-vertex work on the team: the pressure force from the volume's gradient at xs,
 * the inward push k_A, the prediction (predict_item), and after the sweeps the velocities
 * (velocity_item). Each vertex's arithmetic is the same on any thread. */
#define VERTEX_CHUNK 1024u

typedef struct substep_job {
    const shell_state *s;
    double *xs, *v, *q, *grad;
    const double *normals;
    double pressure, h, keep;
} substep_job;

static void vertex_range(const shell_mesh *m, uint32_t item, uint32_t *first, uint32_t *last)
{
    *first = item * VERTEX_CHUNK;
    *last = m->n - *first < VERTEX_CHUNK ? m->n : *first + VERTEX_CHUNK;
}

static void predict_item(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    const substep_job *j = user;
    const shell_mesh *m = j->s->m;
    const shell_params *p = j->s->p;
    const int push = j->s->aniso_count && p->aniso_kA != 0;
    uint32_t first, last;
    vertex_range(m, item, &first, &last);
    shell_volume_gradient(m, j->xs, j->grad, first, last);
    for (uint32_t i = first; i < last; i++) {
        double w = m->inv_mass[i];
        for (int c = 0; c < 3; c++) {
            size_t k = 3 * (size_t)i + (size_t)c;
            double force = -j->pressure * j->grad[k];
            /* k_A is a pressure: times the vertex's rest area (its mass / density). */
            if (push && p->aniso_region[i]) force -= p->aniso_kA * j->normals[k] / (p->density * w);
            j->v[k] = j->keep * (j->v[k] + j->h * w * force);
            j->q[k] = j->xs[k] + j->h * j->v[k];
        }
    }
}

static void velocity_item(void *user, uint32_t item, uint32_t worker)
{
    (void)worker;
    const substep_job *j = user;
    uint32_t first, last;
    vertex_range(j->s->m, item, &first, &last);
    for (size_t k = 3 * (size_t)first; k < 3 * (size_t)last; k++) {
        j->v[k] = (j->q[k] - j->xs[k]) / j->h;
        j->xs[k] = j->q[k];
    }
}

static mk_result simulate(const shell_mesh *m, const shell_params *p, mk_team *team, mk_arena *arena,
                          void (*progress)(void *user, double fraction), void *user, shell_run *run, mk_error *err)
{
    shell_state s = { .m = m, .p = p, .team = team };
    size_t n3 = 3 * (size_t)m->n;
    mk_result r = setup_region(&s, arena, err);
    if (r == MK_OK) r = setup_hinges(&s, arena, err);
    if (r == MK_OK) r = shell_sweep_order_build(m->tris, 3, m->tri_count, m->n, arena, &s.tri_order, err);
    if (r == MK_OK) r = shell_sweep_order_build(m->hinges, 4, m->hinge_count, m->n, arena, &s.hinge_order, err);
    if (r != MK_OK) return r;
    double *x = mk_arena_array(arena, n3, sizeof(double));
    double *v = mk_arena_array(arena, n3, sizeof(double));
    double *q = mk_arena_array(arena, n3, sizeof(double));
    double *grad = mk_arena_array(arena, n3, sizeof(double));
    double *normals = mk_arena_array(arena, n3, sizeof(double));
    double *xs = mk_arena_array(arena, n3, sizeof(double));
    s.lambda = mk_arena_array(arena, (size_t)m->tri_count + m->hinge_count + s.aniso_count + 1, sizeof(double));
    run->positions = mk_arena_array(arena, n3 * ((size_t)p->frames + 1), sizeof(float));
    run->stats = mk_arena_array(arena, (size_t)p->frames + 1, sizeof(shell_frame_stats));
    shell_collider *collider = p->thickness > 0 ? shell_collider_create(m, arena) : NULL;
    if (!x || !v || !q || !xs || !grad || !normals || !s.lambda || !run->positions || !run->stats || (p->thickness > 0 && !collider))
        return mk_error_oom(err, "shell simulation (positions of every frame)");
    memcpy(x, m->rest, n3 * sizeof(double));
    memset(v, 0, n3 * sizeof(double));
    for (size_t i = 0; i < n3; i++) run->positions[i] = (float)x[i];
    double energy[3];
    sweep(&s, x, -1, energy);
    run->stats[0] = (shell_frame_stats){ .volume_ratio = 1, .membrane = energy[0], .bending = energy[1], .aniso = energy[2] };
    uint32_t substeps = run->substeps = shell_substeps(m, p);
    double h = p->dt / substeps, alpha = 1 / (h * h), keep = pow(1 - p->damping, 1.0 / substeps);
    size_t nlambda = (size_t)m->tri_count + m->hinge_count + s.aniso_count;
    const uint32_t vertex_items = (m->n + VERTEX_CHUNK - 1) / VERTEX_CHUNK;
    for (uint32_t f = 1; f <= p->frames; f++) {
        double t0 = bake_now();
        shell_frame_stats *st = &run->stats[f];
        memset(st, 0, sizeof *st);
        /* Substeps: prediction under the pressure force -P dV/dx_i (= -P sum over its triangles
         * A_j n_j / 3) plus the inward push k_A on the region's vertices, then the sweeps, then
         * velocities from positions. */
        memcpy(xs, x, n3 * sizeof(double));
        for (uint32_t sub = 1; sub <= substeps; sub++) {
            double time = (f - 1) * p->dt + sub * h;
            double pressure = p->ramp > 0 && time < p->ramp ? p->pressure * time / p->ramp : p->pressure;
            if (s.aniso_count && p->aniso_kA != 0) shell_vertex_normals(m, xs, normals);
            substep_job job = { .s = &s, .xs = xs, .v = v, .q = q, .grad = grad, .normals = normals,
                                .pressure = pressure, .h = h, .keep = keep };
            mk_team_for(s.team, vertex_items, predict_item, &job);
            if (s.aniso_count) {
                shell_vertex_normals(m, q, normals);
                update_signs(&s, q, normals);
            }
            memset(s.lambda, 0, nlambda * sizeof(double));
            for (uint32_t it = 0; it < p->iterations; it++) sweep(&s, q, alpha, energy);
            mk_team_for(s.team, vertex_items, velocity_item, &job);
        }
        double tc = bake_now();
        if (p->thickness > 0) {
            r = shell_collide(collider, m, x, q, p->thickness, s.team, arena, &st->vt_hits, &st->ee_hits, &st->collision_rounds, err);
            if (r != MK_OK) return r;
        }
        st->ms_collision = 1000 * (bake_now() - tc);
        for (size_t k = 0; k < n3; k++)
            if (!isfinite(q[k]))
                return mk_error_set(err, MK_ERROR_NOT_FINITE, UINT64_MAX,
                                    "the simulation diverged at frame %u (positions not finite): lower dt or pressure, "
                                    "or raise the stiffness", f);
        for (size_t k = 0; k < n3; k += 3) {
            /* A vertex the collisions moved gets its mean velocity over the frame (inelastic). */
            if (q[k] != xs[k] || q[k + 1] != xs[k + 1] || q[k + 2] != xs[k + 2])
                for (size_t c = k; c < k + 3; c++) v[c] = (q[c] - x[c]) / p->dt;
            for (size_t c = k; c < k + 3; c++) {
                x[c] = q[c];
                run->positions[n3 * f + c] = (float)x[c];
            }
        }
        sweep(&s, x, -1, energy);
        st->time = f * p->dt;
        st->volume_ratio = shell_volume(m, x, NULL) / m->volume0;
        st->membrane = energy[0];
        st->bending = energy[1];
        st->aniso = energy[2];
        st->ms_step = 1000 * (bake_now() - t0);
        run->frames = f;
        if (progress) progress(user, (double)f / p->frames);
        if (st->volume_ratio < p->epsilon) {
            run->stopped_by_epsilon = 1;
            break;
        }
    }
    return MK_OK;
}

mk_result shell_simulate(const shell_mesh *m, const shell_params *p, mk_arena *arena,
                         void (*progress)(void *user, double fraction), void *user, shell_run *run,
                         mk_error *err)
{
    memset(run, 0, sizeof *run);
    /* Threads for the sweeps: no more than a phase has parts (shell_order.c). */
    uint32_t parts = shell_sweep_parts(m->tri_count), hinge_parts = shell_sweep_parts(m->hinge_count);
    mk_team *team = mk_team_create(mk_parallel_threads(p->threads, parts > hinge_parts ? parts : hinge_parts));
    mk_result r = simulate(m, p, team, arena, progress, user, run, err);
    mk_team_destroy(team);
    return r;
}

/* Writes the log into buf (NULL: only counts) and returns its length, or -1 on an encoding error. */
static long format_log(const shell_run *run, char *buf, size_t cap)
{
    size_t n = 0;
    int w = snprintf(buf, cap, "frame,time,volume_ratio,membrane_energy,bending_energy,aniso_energy,"
                               "vt_collisions,ee_collisions,collision_rounds,ms_frame,ms_collision\n");
    for (uint32_t k = 0; w >= 0; k++) {
        n += (size_t)w;
        if (k > run->frames) return (long)n;
        const shell_frame_stats *s = &run->stats[k];
        w = snprintf(buf ? buf + n : NULL, buf ? cap - n : 0, "%u,%.6g,%.9g,%.9g,%.9g,%.9g,%u,%u,%u,%.3f,%.3f\n", k,
                     s->time, s->volume_ratio, s->membrane, s->bending, s->aniso, s->vt_hits, s->ee_hits,
                     s->collision_rounds, s->ms_step, s->ms_collision);
    }
    return -1;
}

char *shell_log_csv(const shell_run *run, mk_arena *arena, size_t *size)
{
    long n = format_log(run, NULL, 0);
    char *buf = n >= 0 ? mk_arena_alloc(arena, (size_t)n + 1) : NULL;
    if (!buf) return NULL;
    format_log(run, buf, (size_t)n + 1);
    *size = (size_t)n;
    return buf;
}
