/*
 * capi_demo: the periodic-contact C API from C.
 *
 *   cc examples/capi_demo.c -Iinclude -Ltarget/release -lperiodic_contact \
 *      -Wl,-rpath,$PWD/target/release -o capi_demo
 *   ./capi_demo fmu/scenes/rigid-stop.toml
 *
 * Prints one "key index value" line per number (%.17g), so a test can compare them with the
 * Rust API: the scene's displacement and velocity of DOF 0; the same scene re-solved with
 * frequency*1.05 and force scale 2 (warm-started); a 2-DOF structure given as matrices; and
 * the error message of a scene file that does not exist.
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
    snprintf(key, sizeof key, "%s.x", prefix);
    if (print_series(key, r, 0, pc_result_displacement)) return 1;
    snprintf(key, sizeof key, "%s.v", prefix);
    if (print_series(key, r, 0, pc_result_velocity)) return 1;
    for (size_t i = 0; i < pc_result_contact_count(r); i++) {
        snprintf(key, sizeof key, "%s.force%zu", prefix, i);
        if (print_series(key, r, i, pc_result_contact_force)) return 1;
    }
    for (size_t i = 0; i < pc_result_warning_count(r); i++)
        fprintf(stderr, "%s warning: %s\n", prefix, pc_result_warning(r, i));
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
    return 0;
}
