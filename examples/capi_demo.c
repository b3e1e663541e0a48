/*
 * capi_demo: the periodic-contact C API from C.
 *
 *   cc examples/capi_demo.c -Iinclude -Ltarget/release -lperiodic_contact \
 *      -Wl,-rpath,$PWD/target/release -o capi_demo
 *   ./capi_demo fmu/scenes/rigid-stop.toml [fmu/scenes/chain-3dof-two-stops.toml forward same]
 *
 * Prints one "key index value" line per number (%.17g), so a test can compare them with the
 * Rust API: the scene's displacement and velocity of DOF 0; the same scene re-solved with
 * frequency*1.05 and force scale 2 (warm-started); a 2-DOF structure given as matrices; and
 * the error message of a scene file that does not exist. With a second scene (with contacts)
 * and one pairing per contact: the problem's DOF count and each contact's DOF, direction and
 * pairing as set, each contact's force, gap and paired gap, max |force*paired_gap|, and the
 * warm-start outcome and solver path of a cold solve and of a warm re-solve. Last, a rigid stop
 * with sticking (notes 6.3: m = 1, c = 0.1, k = 1, F = 1, w = 1, gap 0.5, cds, k = 256) solved
 * with the polish: its status, events, and displacement, velocity, force and gap at times
 * between the instants (exact), a fallback (no contact outputs: the events cannot be read), then
 * the same without the polish (interpolated samples).
 */
#include <stdio.h>
#include <stdlib.h>
#include "periodic_contact.h"

static int fail(const char *what) {
    fprintf(stderr, "capi_demo: %s: %s\n", what, pc_last_error());
    return 1;
}

static int print_series(const char *key, const pc_result *r, size_t dof,
                        int (*get)(const pc_result *, size_t, double *, size_t)) {
    size_t k = pc_result_steps(r);
    double *buf = malloc(k * sizeof *buf);
    if (!buf) return 1;
    if (get(r, dof, buf, k) != PC_OK) {
        free(buf);
        return fail(key);
    }
    for (size_t j = 0; j < k; j++) printf("%s %zu %.17g\n", key, j, buf[j]);
    free(buf);
    return 0;
}

static int print_result(const char *prefix, const pc_result *r) {
    char key[64];
    size_t size = 0, pivots = 0;
    double residual = 0;
    printf("%s.steps 0 %zu\n", prefix, pc_result_steps(r));
    printf("%s.period 0 %.17g\n", prefix, pc_result_period(r));
    if (pc_result_lcp(r, &size, &pivots, &residual, NULL) != PC_OK) return fail("lcp");
    printf("%s.lcp_size 0 %zu\n%s.pivots 0 %zu\n", prefix, size, prefix, pivots);
    int estimated = 0;
    double estimate = 0, relative = 0;
    const char *method = NULL;
    if (pc_result_accuracy(r, &estimated, &estimate, &relative, &method) != PC_OK) return fail("accuracy");
    printf("%s.accuracy 0 %d\n%s.accuracy 1 %.17g\n%s.accuracy 2 %.17g\n", prefix, estimated, prefix, estimate, prefix, relative);
    printf("%s.accuracy_method 0 %s\n", prefix, method);
    snprintf(key, sizeof key, "%s.x", prefix);
    if (print_series(key, r, 0, pc_result_displacement)) return 1;
    snprintf(key, sizeof key, "%s.v", prefix);
    if (print_series(key, r, 0, pc_result_velocity)) return 1;
    for (size_t i = 0; i < pc_result_contact_count(r); i++) {
        snprintf(key, sizeof key, "%s.force%zu", prefix, i);
        if (print_series(key, r, i, pc_result_contact_force)) return 1;
    }
    for (size_t i = 0; i < pc_result_friction_count(r); i++) {
        snprintf(key, sizeof key, "%s.friction_force%zu", prefix, i);
        if (print_series(key, r, i, pc_result_friction_force)) return 1;
    }
    for (size_t i = 0; i < pc_result_warning_count(r); i++)
        fprintf(stderr, "%s warning: %s\n", prefix, pc_result_warning(r, i));
    return 0;
}

/* Section 5: per-contact pairing and the inspection accessors. */
static int contacts_demo(const char *path, int npairing, char **pairing) {
    pc_problem *p = pc_problem_from_scene_file(path);
    if (!p) return fail("pc_problem_from_scene_file (contacts)");
    size_t m = pc_problem_contact_count(p);
    printf("contacts.dof_count 0 %zu\ncontacts.count 0 %zu\n", pc_problem_dof_count(p), m);
    for (size_t i = 0; i < m && (int)i < npairing; i++)
        if (pc_problem_set_contact_pairing(p, i, pairing[i]) != PC_OK) return fail("set_contact_pairing");
    for (size_t i = 0; i < m; i++) {
        size_t dof = 0;
        int direction = 0;
        if (pc_problem_contact(p, i, &dof, &direction) != PC_OK) return fail("pc_problem_contact");
        printf("contacts.dof %zu %zu\ncontacts.direction %zu %d\n", i, dof, i, direction);
        printf("contacts.pairing %zu %s\n", i, pc_problem_contact_pairing(p, i));
    }
    printf("contacts.bad_index 0 %d\n", pc_problem_set_contact_pairing(p, m, "same"));
    printf("contacts.bad_name 0 %d\n", pc_problem_set_contact_pairing(p, 0, "backward"));
    const char *label[2] = {"cold", "warm"};
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1 && pc_problem_set_frequency(p, 1.001 * pc_problem_frequency(p)) != PC_OK)
            return fail("set_frequency (contacts)");
        pc_result *r = pc_problem_solve(p);
        if (!r) return fail("pc_problem_solve (contacts)");
        size_t k = pc_result_steps(r), pivots = 0;
        double *f = malloc(k * sizeof *f), *g = malloc(k * sizeof *g);
        if (!f || !g) return 1;
        for (size_t i = 0; pass == 0 && i < pc_result_contact_count(r); i++) {
            char key[64];
            printf("contacts.result_pairing %zu %s\n", i, pc_result_contact_pairing(r, i));
            snprintf(key, sizeof key, "contacts.force%zu", i);
            if (print_series(key, r, i, pc_result_contact_force)) return 1;
            snprintf(key, sizeof key, "contacts.gap%zu", i);
            if (print_series(key, r, i, pc_result_contact_gap)) return 1;
            snprintf(key, sizeof key, "contacts.paired_gap%zu", i);
            if (print_series(key, r, i, pc_result_contact_paired_gap)) return 1;
            if (pc_result_contact_force(r, i, f, k) != PC_OK) return fail("force");
            if (pc_result_contact_paired_gap(r, i, g, k) != PC_OK) return fail("paired_gap");
            double worst = 0;
            for (size_t j = 0; j < k; j++) {
                double c = f[j] * g[j] < 0 ? -f[j] * g[j] : f[j] * g[j];
                if (c > worst) worst = c;
            }
            printf("contacts.complementarity %zu %.17g\n", i, worst);
        }
        free(f);
        free(g);
        const char *outcome = NULL;
        if (pc_result_warm_start(r, &outcome, &pivots) != PC_OK) return fail("warm_start");
        printf("contacts.%s.warm_start 0 %s\ncontacts.%s.pivots 0 %zu\n", label[pass], outcome,
               label[pass], pivots);
        printf("contacts.%s.path 0 %s\n", label[pass], pc_result_lcp_path(r));
        pc_result_free(r);
    }
    pc_problem_free(p);
    return 0;
}

/* Section 6: the event-fitted polish and the response between the instants. */
static int polish_demo(void) {
    const double m = 1.0, k = 1.0, c = 0.1;
    const double t[6] = {0.37, 1.234, 2.5, 3.95, 5.9, -1.31}; /* between instants; any real */
    for (int on = 1; on >= 0; on--) {
        const char *pre = on ? "polish" : "plain";
        pc_problem *p = pc_problem_from_matrices(1, &m, &k, &c, 1.0, "cds", 256);
        if (!p) return fail("pc_problem_from_matrices (polish)");
        if (pc_problem_add_force(p, 0, 1.0, 1, 0.0) != PC_OK) return fail("add_force (polish)");
        if (pc_problem_add_contact(p, 0, 1, 0.5, 0.0, NULL) != PC_OK) return fail("add_contact (polish)");
        if (pc_problem_set_error_estimate(p, 0) != PC_OK) return fail("set_error_estimate");
        if (pc_problem_set_polish(p, on) != PC_OK) return fail("set_polish");
        pc_result *r = pc_problem_solve(p);
        if (!r) return fail("pc_problem_solve (polish)");
        int status = -1;
        const char *reason = NULL;
        if (pc_result_polish(r, &status, &reason) != PC_OK) return fail("pc_result_polish");
        printf("%s.status 0 %d\n%s.reason 0 %s\n", pre, status, pre, reason);
        size_t n = pc_result_event_count(r);
        printf("%s.events 0 %zu\n", pre, n);
        for (size_t i = 0; i < n; i++) {
            double time = 0, impulse = 0;
            size_t contact = 9;
            const char *kind = NULL;
            if (pc_result_event(r, i, &time, &contact, &kind, &impulse) != PC_OK) return fail("pc_result_event");
            printf("%s.event_time %zu %.17g\n%s.event_kind %zu %s\n%s.event_impulse %zu %.17g\n", pre, i,
                   time, pre, i, kind, pre, i, impulse);
        }
        printf("%s.bad_event 0 %d\n", pre, pc_result_event(r, n, NULL, NULL, NULL, NULL));
        for (int i = 0; i < 6; i++) {
            double x = 0, v = 0, f = 0, g = 0;
            int exact = -1, exact_c = -1;
            if (pc_result_state_at(r, 0, t[i], &x, &v, &exact) != PC_OK) return fail("pc_result_state_at");
            if (pc_result_contact_at(r, 0, t[i], &f, &g, &exact_c) != PC_OK) return fail("pc_result_contact_at");
            printf("%s.t %d %.17g\n%s.x %d %.17g\n%s.v %d %.17g\n%s.force %d %.17g\n%s.gap %d %.17g\n",
                   pre, i, t[i], pre, i, x, pre, i, v, pre, i, f, pre, i, g);
            printf("%s.exact %d %d\n%s.exact_contact %d %d\n", pre, i, exact, pre, i, exact_c);
        }
        printf("%s.bad_dof 0 %d\n", pre, pc_result_state_at(r, 5, 1.0, NULL, NULL, NULL));
        pc_result_free(r);
        if (on) {
            /* Without contact outputs the events cannot be read: a fallback, with its reason. */
            const size_t dof = 0;
            if (pc_problem_set_outputs(p, &dof, 1, &dof, 1, NULL, 0, 0) != PC_OK) return fail("set_outputs");
            r = pc_problem_solve(p);
            if (!r) return fail("pc_problem_solve (fallback)");
            double x = 0;
            int exact = -1;
            if (pc_result_polish(r, &status, &reason) != PC_OK) return fail("pc_result_polish (fallback)");
            if (pc_result_state_at(r, 0, 1.0, &x, NULL, &exact) != PC_OK) return fail("state_at (fallback)");
            printf("fallback.status 0 %d\nfallback.reason 0 %s\nfallback.exact 0 %d\n", status, reason, exact);
            for (size_t i = 0; i < pc_result_warning_count(r); i++)
                printf("fallback.warning %zu %s\n", i, pc_result_warning(r, i));
            pc_result_free(r);
        }
        pc_problem_free(p);
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s SCENE.toml\n", argv[0]);
        return 2;
    }
    printf("version 0 %s\n", pc_version());

    /* 1. A scene file, solved as is. */
    pc_problem *p = pc_problem_from_scene_file(argv[1]);
    if (!p) return fail("pc_problem_from_scene_file");
    pc_result *r = pc_problem_solve(p);
    if (!r) return fail("pc_problem_solve");
    if (print_result("scene", r)) return 1;
    pc_result_free(r);

    /* 2. The same problem after a small change of frequency and a force scale: warm-started. */
    double w = pc_problem_frequency(p);
    if (pc_problem_set_frequency(p, 1.05 * w) != PC_OK) return fail("set_frequency");
    if (pc_problem_set_force_scale(p, 2.0) != PC_OK) return fail("set_force_scale");
    r = pc_problem_solve(p);
    if (!r) return fail("pc_problem_solve (tuned)");
    if (print_result("tuned", r)) return 1;
    pc_result_free(r);
    pc_problem_free(p);

    /* 3. A 2-DOF structure from matrices, forced on DOF 1, Fourier collocation. */
    const double M[4] = {2.0, 0.3, 0.3, 1.0};
    const double K[4] = {5.0, -2.0, -2.0, 3.0};
    const double C[4] = {0.1, -0.02, -0.02, 0.05};
    p = pc_problem_from_matrices(2, M, K, C, 1.7, "fourier", 32);
    if (!p) return fail("pc_problem_from_matrices");
    if (pc_problem_set_parallel(p, 0) != PC_OK) return fail("set_parallel");
    if (pc_problem_add_force(p, 1, 0.8, 1, 0.4) != PC_OK) return fail("add_force");
    r = pc_problem_solve(p);
    if (!r) return fail("pc_problem_solve (matrices)");
    if (print_result("matrices", r)) return 1;
    pc_result_free(r);

    /* 4. Errors come back as codes and messages, never as crashes. */
    int code = pc_problem_add_force(p, 7, 1.0, 1, 0.0); /* DOF 7 does not exist */
    printf("bad_dof.code 0 %d\n", code);
    printf("bad_dof.message 0 %s\n", pc_last_error());
    pc_problem_free(p);
    pc_problem *missing = pc_problem_from_scene_file("/nonexistent/scene.toml");
    printf("missing.null 0 %d\n", missing == NULL);
    printf("missing.message 0 %s\n", pc_last_error());
    printf("null.code 0 %d\n", pc_problem_set_frequency(NULL, 1.0));
    pc_problem_free(NULL);
    pc_result_free(NULL);

    /* 5. Contacts: per-contact pairing, the problem's and the result's inspection accessors. */
    if (argc >= 3 && contacts_demo(argv[2], argc - 3, argv + 3)) return 1;

    /* 6. The event-fitted polish: outcome, events, the exact orbit between the instants. */
    return polish_demo();
}
