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
 *     return NULL on failure. pc_last_error() then gives the reason.
 *   - No exception/panic crosses the boundary (a caught panic is PC_ERROR_INTERNAL).
 *
 * Lifetimes and ownership
 *   - A pc_problem lives until pc_problem_free; a pc_result until pc_result_free. A result does
 *     not borrow its problem: either may be freed first. Free each handle exactly once.
 *   - Strings from pc_result_warning, pc_result_json, pc_result_warm_start,
 *     pc_result_lcp_path, pc_result_accuracy's method and pc_result_polish's reason are owned by
 *     their result: valid until pc_result_free, never free them.
 *   - pc_version, the pairing names ("same", "forward") and the event kinds of pc_result_event
 *     have static storage.
 *   - pc_last_error's string is thread-local: valid until the next failing call on the same
 *     thread (a successful call makes it ""; copy it if you need it longer). Never free it.
 *   - Copy functions write into caller buffers; the library keeps no caller pointer.
 *
 * Const-ness and thread safety
 *   - Functions taking a const handle only read it. Distinct problems (and their results) may
 *     be used from distinct threads at the same time.
 *   - Const readers of one result may run concurrently, pc_result_json included (its text is
 *     made once, on the first call, behind a once-only cell).
 *   - A problem must not be mutated (pc_problem_set_*, pc_problem_add_*, pc_problem_solve,
 *     pc_problem_free) while another thread reads or solves it: serialise those calls.
 *
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

/* pc_result_polish's status. */
#define PC_POLISH_OFF 0      /* not asked                                                     */
#define PC_POLISH_POLISHED 1 /* the samples and pc_result_state_at are the exact orbit's      */
#define PC_POLISH_FALLBACK 2 /* the polish failed (reason given): the LCP's samples are kept  */

typedef struct PcProblem pc_problem;
typedef struct PcResult pc_result;

/* Library version, static storage. */
const char *pc_version(void);
/* Message of the last failed call on this thread ("" after a success): thread-local, valid
 * until the next failing call on this thread; never free it. */
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
/* The pairing of contact `contact` alone ("same", "forward", or NULL to drop the override);
 * it wins over pc_problem_set_pairing. PC_ERROR_ARGUMENT for an index out of range,
 * PC_ERROR_INPUT for another name. The scene key `pairing` of a [[contact]] does the same. */
int pc_problem_set_contact_pairing(pc_problem *p, size_t contact, const char *pairing);
/* 1 (default): factorise the harmonics on rayon's global thread pool; 0: on the calling thread. */
int pc_problem_set_parallel(pc_problem *p, int parallel);
/* Tunable values, applied at the next solve. */
int pc_problem_set_frequency(pc_problem *p, double omega);   /* rad/s, > 0             */
int pc_problem_set_force_scale(pc_problem *p, double scale); /* times every force      */
int pc_problem_set_gap_offset(pc_problem *p, double offset); /* plus every clearance   */
int pc_problem_set_motion_scale(pc_problem *p, double scale);/* times obstacle motion  */
double pc_problem_frequency(const pc_problem *p);
/* DOFs in the user's numbering: the scene's full model for a reduced or clamped scene (fixed
 * DOFs among them cannot be output), n for pc_problem_from_matrices. 0 for NULL. */
size_t pc_problem_dof_count(const pc_problem *p);
/* Number of contacts (0 for NULL). */
size_t pc_problem_contact_count(const pc_problem *p);
/* Contact i's DOF in the user's numbering and its direction (+1/-1); outputs may be NULL.
 * PC_ERROR_ARGUMENT for a NULL handle or i out of range. */
int pc_problem_contact(const pc_problem *p, size_t i, size_t *dof, int *direction);
/* The pairing contact i will be solved with: "same" or "forward" (static storage);
 * NULL for a NULL handle or i out of range. */
const char *pc_problem_contact_pairing(const pc_problem *p, size_t i);
/* on = 1 (default, or the scene's [discretization] error_estimate): every solve also
 * estimates its error by a second solve at k/2 (Richardson); 0: skip it, for speed. */
int pc_problem_set_error_estimate(pc_problem *p, int on);
/* CPU seconds the estimate's neighbour solves may take together (default 30, >= 0); past it the
 * result has no estimate: pc_result_accuracy gives *estimated = 0 and the method says why. */
int pc_problem_set_error_estimate_budget(pc_problem *p, double seconds);
/* on = 1 (or the scene's [discretization] polish = true): every solve is refined by the
 * event-fitted polish (exact flows between the events read from the LCP, Newton on the event
 * times and states): the samples become the exact orbit's, with its events and an exact
 * interpolant (pc_result_polish, pc_result_event, pc_result_state_at). A failed polish is no
 * error: the result keeps the LCP's orbit, with PC_POLISH_FALLBACK, its reason and a warning.
 * 0 (default): no polish. */
int pc_problem_set_polish(pc_problem *p, int on);
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
/* The gap each force sample is complementary to: paired_gap[j] = gap[j] ("same") or
 * gap[(j+1) mod k] ("forward"), so a rigid contact has force[j]*paired_gap[j] = 0 (compliant:
 * force[j]*(paired_gap[j] + force[j]/stiffness) = 0). */
int pc_result_contact_paired_gap(const pc_result *r, size_t i, double *out, size_t len);
/* The pairing contact i was solved with ("same"/"forward", static); NULL when out of range. */
const char *pc_result_contact_pairing(const pc_result *r, size_t i);
/* Any output pointer may be NULL. */
int pc_result_lcp(const pc_result *r, size_t *size, size_t *pivots, double *residual,
                  int *warm_start_used);
/* What became of the warm start: *outcome = "cold", "accepted", "repaired" or "rejected"
 * (owned by the result), *pivots = pivots of the solve that gave the answer. Outputs may be NULL. */
int pc_result_warm_start(const pc_result *r, const char **outcome, size_t *pivots);
/* The LCP methods that ran and the fallbacks taken, one line (the JSON's lcp.path); owned by
 * the result; NULL for NULL. */
const char *pc_result_lcp_path(const pc_result *r);
/* The error estimate (the JSON's accuracy): *estimated = 1 with *estimate (length unit, max
 * over the instants and displacement outputs) and *relative (of the peak-to-peak amplitude),
 * or *estimated = 0 and both 0; *method says how, or why there is none (owned by the result).
 * Any output may be NULL. */
int pc_result_accuracy(const pc_result *r, int *estimated, double *estimate, double *relative,
                       const char **method);
/* The polish's outcome: *status = PC_POLISH_OFF, PC_POLISH_POLISHED or PC_POLISH_FALLBACK;
 * *reason = the fallback's cause ("" otherwise; owned by the result). Outputs may be NULL. */
int pc_result_polish(const pc_result *r, int *status, const char **reason);
/* Events of the polished orbit in time order (0 without one). Event i: *time in [0, T),
 * *contact, *kind = "impact", "release", "contact_on" or "contact_off" (static storage),
 * *impulse (> 0 at an impact, else 0). Outputs may be NULL; PC_ERROR_ARGUMENT when i is out
 * of range. */
size_t pc_result_event_count(const pc_result *r);
int pc_result_event(const pc_result *r, size_t i, double *time, size_t *contact,
                    const char **kind, double *impulse);
/* Displacement and velocity of `dof` at any time t (taken modulo T). *exact = 1: the polished
 * orbit's, exact between the instants (any DOF of the user's numbering); *exact = 0: the samples
 * interpolated (trigonometric for fourier, cubic Hermite through (x_j, v_j) otherwise; the DOF
 * needs displacement and velocity outputs). Outputs may be NULL. */
int pc_result_state_at(const pc_result *r, size_t dof, double t, double *displacement,
                       double *velocity, int *exact);
/* Contact i's compressive force and clearance at any time t. *exact = 1: the polished orbit's
 * (a stuck rigid contact's force or stiffness*penetration; an impact is an impulse, see
 * pc_result_event); *exact = 0: the samples interpolated linearly (a rigid contact's force
 * samples are impulse per step / h). Outputs may be NULL. */
int pc_result_contact_at(const pc_result *r, size_t i, double t, double *force, double *gap,
                         int *exact);
/* Friction contacts ([[friction]], the JSON's friction entries), in scene order. The force f
 * acts on the structure as -f along the sliding direction: |f| <= mu*N, f = mu*N*sign(v) while
 * slipping. pc_problem_friction_count: 0 without friction or for NULL. normal_force_scale
 * multiplies every friction contact's normal load N at the next solve (finite, >= 0; 1: the
 * scene's loads). Series at the k instants, PC_ERROR_ARGUMENT when i is out of range or the
 * buffer is NULL or shorter than k: force, slip velocity v (bds1's backward difference; a
 * Jenkins element's slider velocity; 0 while stuck), tangential displacement u (the loop's
 * abscissa), stuck flags (1: |f| < mu*N). pc_result_friction: the energy dissipated per period
 * (force unit x length unit, >= 0) and the slip force mu*N; outputs may be NULL. */
size_t pc_problem_friction_count(const pc_problem *p);
int pc_problem_set_normal_force_scale(pc_problem *p, double scale);
size_t pc_result_friction_count(const pc_result *r);
int pc_result_friction_force(const pc_result *r, size_t i, double *out, size_t len);
int pc_result_friction_slip_velocity(const pc_result *r, size_t i, double *out, size_t len);
int pc_result_friction_displacement(const pc_result *r, size_t i, double *out, size_t len);
int pc_result_friction_stuck(const pc_result *r, size_t i, int *out, size_t len);
int pc_result_friction(const pc_result *r, size_t i, double *dissipated_energy, double *slip_force);
size_t pc_result_warning_count(const pc_result *r);
/* Warning i, owned by the result (valid until pc_result_free); NULL when out of range. */
const char *pc_result_warning(const pc_result *r, size_t i);
/* The result as the CLI's JSON (with each contact's paired_gap, lcp.warm_start and lcp.path).
   The string is owned by the result: valid until pc_result_free(r), never free it yourself.
   Made once on the first call; calls on the same const result may run concurrently. */
const char *pc_result_json(const pc_result *r);
void pc_result_free(pc_result *r);

/* ---- branches and stability (issue 13) ----------------------------------------------- */
/* Each pc_problem_solve continues the previous result's orbit along its branch (same number of
 * instants, a difference scheme's step map): where the branch ends at a fold between the old and
 * the new values the answer is the orbit that exists, and pc_result_jump says so. */

/* Whether every solve also computes the orbit's Floquet stability (on = 1; default 0, or the
 * scene's [output] stability). */
int pc_problem_set_stability(pc_problem *p, int on);
/* The Floquet stability (the discrete monodromy of the step map on the orbit's active sets, as
 * periodic-contact continue): *computed = 1 with *stable (1: every multiplier inside the unit
 * circle) and *multiplier (the largest modulus), or *computed = 0, both 0 and *why saying why
 * not (owned by the result; "" when computed). Any output may be NULL. */
int pc_result_stability(const pc_result *r, int *computed, int *stable, double *multiplier,
                        const char **why);
/* *jumped = 1 when this solve jumped because the branch ended at a fold: *fold_frequency
 * [rad/s] where it turned back, the amplitudes (half the largest peak-to-peak of the
 * displacement outputs) before and after; else all 0. *jumps: the problem's jumps so far. Any
 * output may be NULL. */
int pc_result_jump(const pc_result *r, int *jumped, double *fold_frequency,
                   double *from_amplitude, double *to_amplitude, size_t *jumps);

#ifdef __cplusplus
}
#endif

#endif /* PERIODIC_CONTACT_H */
