/*
 * periodic_contact.h: the native C API of periodic-contact.
 *
 * Steady-state periodic responses of structures under unilateral contact, computed as one
 * linear complementarity problem over a discretised period (Meingast, Legrand & Pierre 2014).
 *
 * Link with -lperiodic_contact (libperiodic_contact.so, built by `cargo build --release`).
 *
 * Conventions
 *   - Opaque handles (pc_problem, pc_result), each freed by its own function; NULL is ignored.
 *   - Functions returning int return PC_OK (0) or an error code; functions returning a handle
 *     return NULL on failure. pc_last_error() then gives the reason (per thread, like errno;
 *     valid until the next call on this thread).
 *   - No exception/panic crosses the boundary. A handle is not thread-safe; distinct handles
 *     may be used from distinct threads.
 *   - Units are the scene's (consistent: e.g. kg, N/m, m, s); frequencies are rad/s.
 *     Contact i with direction s on DOF d keeps s*x[d] <= gap(t); its force >= 0 is
 *     compressive, its gap >= 0 is the clearance.
 *   - Time series have k = pc_result_steps() values at t_j = j*T/k; copy functions need a
 *     buffer of at least k doubles.
 */
#ifndef PERIODIC_CONTACT_H
#define PERIODIC_CONTACT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PC_OK 0
#define PC_ERROR_ARGUMENT 1 /* NULL pointer, index out of range, buffer too small, bad value */
#define PC_ERROR_INPUT 2    /* invalid scene or model (the message names field and value)   */
#define PC_ERROR_SOLVER 3   /* singular operator, LCP not solved, non-finite response        */
#define PC_ERROR_INTERNAL 4 /* internal error (a caught panic)                               */

typedef struct PcProblem pc_problem;
typedef struct PcResult pc_result;

/* Library version, static storage. */
const char *pc_version(void);
/* Message of the last failed call on this thread ("" after a success). */
const char *pc_last_error(void);

/* ---- problems ------------------------------------------------------------------------ */

/* A scene file (TOML, the scene contract of the README). */
pc_problem *pc_problem_from_scene_file(const char *path);
/* Scene text (TOML). */
pc_problem *pc_problem_from_scene_text(const char *toml);
/* n x n row-major M, K and C (damping may be NULL), no forces or contacts yet; scheme is
 * "bds1", "bds2", "cds", "galerkin" or "fourier"; steps = instants per period.
 * Outputs: displacement and velocity of every DOF, and every contact. */
pc_problem *pc_problem_from_matrices(size_t n, const double *mass, const double *stiffness,
                                     const double *damping, double frequency,
                                     const char *scheme, size_t steps);
/* f[dof] += amplitude*cos(harmonic*w*t + phase). */
int pc_problem_add_force(pc_problem *p, size_t dof, double amplitude, unsigned harmonic,
                         double phase);
/* A unilateral contact: direction +1 keeps x[dof] <= gap, -1 keeps x[dof] >= -gap;
 * stiffness > 0 compliant, 0 rigid. *index (may be NULL) receives its index. */
int pc_problem_add_contact(pc_problem *p, size_t dof, int direction, double gap,
                           double stiffness, size_t *index);
/* Moving obstacle: gap(t) += amplitude*cos(harmonic*w*t + phase) for contact `contact`. */
int pc_problem_add_contact_motion(pc_problem *p, size_t contact, double amplitude,
                                  unsigned harmonic, double phase);
/* Which responses to recover (arrays of DOF indices; NULL allowed with count 0). */
int pc_problem_set_outputs(pc_problem *p, const size_t *displacement, size_t n_displacement,
                           const size_t *velocity, size_t n_velocity,
                           const size_t *acceleration, size_t n_acceleration, int contacts);
/* "same", "forward", or NULL for the per-contact default. */
int pc_problem_set_pairing(pc_problem *p, const char *pairing);
/* 1 (default): factorise the harmonics on rayon's global thread pool; 0: on the calling thread. */
int pc_problem_set_parallel(pc_problem *p, int parallel);
/* Tunable values, applied at the next solve. */
int pc_problem_set_frequency(pc_problem *p, double omega);   /* rad/s, > 0             */
int pc_problem_set_force_scale(pc_problem *p, double scale); /* times every force      */
int pc_problem_set_gap_offset(pc_problem *p, double offset); /* plus every clearance   */
int pc_problem_set_motion_scale(pc_problem *p, double scale);/* times obstacle motion  */
double pc_problem_frequency(const pc_problem *p);
/* Solves; warm-started from this problem's previous solve. NULL on failure. */
pc_result *pc_problem_solve(pc_problem *p);
void pc_problem_free(pc_problem *p);

/* ---- results ------------------------------------------------------------------------- */

size_t pc_result_steps(const pc_result *r);
double pc_result_period(const pc_result *r);
int pc_result_time(const pc_result *r, double *out, size_t len);
int pc_result_displacement(const pc_result *r, size_t dof, double *out, size_t len);
int pc_result_velocity(const pc_result *r, size_t dof, double *out, size_t len);
int pc_result_acceleration(const pc_result *r, size_t dof, double *out, size_t len);
size_t pc_result_contact_count(const pc_result *r);
int pc_result_contact_force(const pc_result *r, size_t i, double *out, size_t len);
int pc_result_contact_gap(const pc_result *r, size_t i, double *out, size_t len);
/* Any output pointer may be NULL. */
int pc_result_lcp(const pc_result *r, size_t *size, size_t *pivots, double *residual,
                  int *warm_start_used);
size_t pc_result_warning_count(const pc_result *r);
const char *pc_result_warning(const pc_result *r, size_t i);
/* The result as the CLI's JSON; valid as long as the result. */
const char *pc_result_json(pc_result *r);
void pc_result_free(pc_result *r);

#ifdef __cplusplus
}
#endif

#endif /* PERIODIC_CONTACT_H */
