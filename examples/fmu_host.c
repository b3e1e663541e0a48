/*
 * fmu_host: a small FMI 2.0 co-simulation host in C that drives the PeriodicContact FMU through
 * dlopen, as a C importer would (no FMI library, no Rust on the host side).
 *
 *   cc -std=c99 -O1 -g examples/fmu_host.c -ldl -o fmu_host
 *   unzip -d rigid rigid.fmu          # an FMU from `periodic-contact fmu SCENE.toml -o rigid.fmu`
 *   ./fmu_host rigid                  # instantiate, initialise, two periods, outputs, free
 *   ./fmu_host rigid --steps 10000000 --rss-every 1000000   # the long run
 *
 * DIR is the unzipped FMU: DIR/modelDescription.xml (the GUID and the value references are read
 * from it), DIR/binaries/linux64/PeriodicContact.so (all 34 FMI 2 CS functions are looked up) and
 * DIR/resources (passed as a percent-encoded file:// URI of its absolute path).
 *
 * Options:
 *   --periods P         step P periods of k steps each (h = T/k, T = 2*pi/frequency, k = steps);
 *                       default 2; prints "output NAME VALUE" (%.17g) for every Real output at
 *                       the end of each period
 *   --steps N           step N times instead (h = T/k), reading every Real output after each step
 *   --rss-every M       with --steps: print "rss STEP KIB" (resident size from /proc/self/statm)
 *                       every M steps, and once before the first step
 *   --resolve-every R   every R steps set frequency_in alternately to 1.001*w and w (each change
 *                       re-solves, warm-started, at the next step)
 *
 * Prints "steps_per_s X" and "nonfinite N" at the end. Exit status 0 on success, 1 when a call
 * fails or an output is not finite, 2 on bad usage.
 */
#define _XOPEN_SOURCE 700
#include <limits.h>
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- the FMI 2.0 types (fmi2TypesPlatform.h, fmi2FunctionTypes.h) ------------------------ */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean,
                                      fmi2Real);
typedef fmi2Status (*Simple)(fmi2Component);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*GetInteger)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Integer *);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef const char *(*GetString0)(void);

static const char *const FMI2_CS_FUNCTIONS[34] = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal", "fmi2GetInteger",
    "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean",
    "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus",
    "fmi2GetRealStatus", "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus"};

/* ---- the logger: variadic, formats with the format it is given ---------------------------- */
static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String format, ...) {
    (void)env;
    va_list ap;
    va_start(ap, format);
    fprintf(stderr, "[%s|%d|%s] ", instance ? instance : "?", (int)status,
            category ? category : "?");
    vfprintf(stderr, format, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* ---- modelDescription.xml: just enough parsing for the GUID and the Real outputs ----------- */
static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) != 0) { fclose(f); return NULL; }
    long n = ftell(f);
    if (n < 0 || fseek(f, 0, SEEK_SET) != 0) { fclose(f); return NULL; }
    char *buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) { free(buf); buf = NULL; }
    if (buf) buf[n] = '\0';
    fclose(f);
    return buf;
}

/* The value of attribute `name` inside the tag [tag, end), copied into out (size cap). */
static int attribute(const char *tag, const char *end, const char *name, char *out, size_t cap) {
    size_t len = strlen(name);
    for (const char *p = tag; p && p < end; p++) {
        p = strstr(p, name);
        if (!p || p >= end) return 0;
        if (p[-1] == ' ' && p[len] == '=' && p[len + 1] == '"') {
            const char *v = p + len + 2, *q = strchr(v, '"');
            if (!q || q > end || (size_t)(q - v) >= cap) return 0;
            memcpy(out, v, (size_t)(q - v));
            out[q - v] = '\0';
            return 1;
        }
    }
    return 0;
}

#define MAX_VARS 4096
typedef struct {
    char name[128];
    fmi2ValueReference vr;
} Var;

typedef struct {
    char guid[128];
    Var outputs[MAX_VARS]; /* Real outputs */
    size_t n_outputs;
    long frequency, frequency_in, steps; /* value references, -1 when absent */
} Description;

static int parse_description(const char *xml, Description *d) {
    const char *root = strstr(xml, "<fmiModelDescription");
    if (!root || !attribute(root, strchr(root, '>'), "guid", d->guid, sizeof d->guid)) return 0;
    d->n_outputs = 0;
    d->frequency = d->frequency_in = d->steps = -1;
    for (const char *p = strstr(xml, "<ScalarVariable"); p; p = strstr(p + 1, "<ScalarVariable")) {
        const char *tag_end = strchr(p, '>'), *var_end = strstr(p, "</ScalarVariable>");
        char name[128], vr[32], causality[32] = "local";
        if (!tag_end || !var_end || !attribute(p, tag_end, "name", name, sizeof name) ||
            !attribute(p, tag_end, "valueReference", vr, sizeof vr))
            return 0;
        attribute(p, tag_end, "causality", causality, sizeof causality);
        const char *real = strstr(tag_end, "<Real");
        int is_real = real && real < var_end;
        long v = strtol(vr, NULL, 10);
        if (strcmp(name, "frequency") == 0) d->frequency = v;
        if (strcmp(name, "frequency_in") == 0) d->frequency_in = v;
        if (strcmp(name, "steps") == 0) d->steps = v;
        if (is_real && strcmp(causality, "output") == 0 && d->n_outputs < MAX_VARS) {
            Var *o = &d->outputs[d->n_outputs++];
            memcpy(o->name, name, sizeof o->name);
            o->vr = (fmi2ValueReference)v;
        }
    }
    return d->frequency >= 0 && d->steps >= 0 && d->n_outputs > 0;
}

/* Resident set size in KiB (/proc/self/statm, second field, in pages). */
static long rss_kib(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    long size = 0, resident = -1;
    if (!f) return -1;
    if (fscanf(f, "%ld %ld", &size, &resident) != 2) resident = -1;
    fclose(f);
    return resident < 0 ? -1 : resident * 4;
}

/* "file://" + the percent-encoded absolute path of DIR/resources (RFC 3986, as fmpy does). */
static int resource_uri(const char *dir, char *out, size_t cap) {
    char abs[PATH_MAX];
    if (!realpath(dir, abs)) return 0;
    size_t n = (size_t)snprintf(out, cap, "file://");
    const char *parts[2] = {abs, "/resources"};
    for (int p = 0; p < 2; p++)
        for (const unsigned char *c = (const unsigned char *)parts[p]; *c; c++) {
            int plain = (*c >= 'A' && *c <= 'Z') || (*c >= 'a' && *c <= 'z') ||
                        (*c >= '0' && *c <= '9') || strchr("/-._~", *c);
            if (n + 4 >= cap) return 0;
            n += (size_t)(plain ? snprintf(out + n, cap - n, "%c", *c)
                                : snprintf(out + n, cap - n, "%%%02X", *c));
        }
    return 1;
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage(const char *argv0) {
    fprintf(stderr,
            "usage: %s UNZIPPED_FMU_DIR [--periods P | --steps N] [--rss-every M] "
            "[--resolve-every R]\n",
            argv0);
    return 2;
}

int main(int argc, char **argv) {
    if (argc < 2) return usage(argv[0]);
    const char *dir = argv[1];
    long periods = 2, steps_total = -1, rss_every = 0, resolve_every = 0;
    for (int i = 2; i < argc; i++) {
        if (i + 1 >= argc) return usage(argv[0]);
        long v = strtol(argv[i + 1], NULL, 10);
        if (strcmp(argv[i], "--periods") == 0) periods = v;
        else if (strcmp(argv[i], "--steps") == 0) steps_total = v;
        else if (strcmp(argv[i], "--rss-every") == 0) rss_every = v;
        else if (strcmp(argv[i], "--resolve-every") == 0) resolve_every = v;
        else return usage(argv[0]);
        i++;
    }

    char path[4096];
    snprintf(path, sizeof path, "%s/modelDescription.xml", dir);
    char *xml = read_file(path);
    if (!xml) {
        fprintf(stderr, "fmu_host: cannot read %s\n", path);
        return 1;
    }
    Description *d = malloc(sizeof *d);
    if (!d || !parse_description(xml, d)) {
        fprintf(stderr, "fmu_host: %s: no GUID, frequency, steps or Real output found\n", path);
        free(xml);
        free(d);
        return 1;
    }
    free(xml);

    snprintf(path, sizeof path, "%s/binaries/linux64/PeriodicContact.so", dir);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "fmu_host: dlopen %s: %s\n", path, dlerror());
        free(d);
        return 1;
    }
    void *fn[34];
    for (int i = 0; i < 34; i++) {
        fn[i] = dlsym(lib, FMI2_CS_FUNCTIONS[i]);
        if (!fn[i]) {
            fprintf(stderr, "fmu_host: %s: missing %s\n", path, FMI2_CS_FUNCTIONS[i]);
            dlclose(lib);
            free(d);
            return 1;
        }
    }
    /* POSIX: a data pointer from dlsym converts to a function pointer through memcpy. */
#define FN(type, var, index) type var; memcpy(&var, &fn[index], sizeof var)
    FN(GetString0, get_version, 1);
    FN(Instantiate, instantiate, 3);
    FN(FreeInstance, free_instance, 4);
    FN(SetupExperiment, setup_experiment, 5);
    FN(Simple, enter_init, 6);
    FN(Simple, exit_init, 7);
    FN(Simple, terminate, 8);
    FN(GetReal, get_real, 10);
    FN(GetInteger, get_integer, 11);
    FN(SetReal, set_real, 14);
    FN(DoStep, do_step, 27);
    printf("version %s\n", get_version());

    char resources[3 * PATH_MAX + 32];
    if (!resource_uri(dir, resources, sizeof resources)) {
        fprintf(stderr, "fmu_host: %s: no such folder\n", dir);
        free(d);
        dlclose(lib);
        return 1;
    }
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("fmu_host", fmi2CoSimulation, d->guid, resources, &cb, 0, 0);
    int rc = 1;
    double *values = NULL;
    fmi2ValueReference *vrs = NULL;
    if (!c) {
        fprintf(stderr, "fmu_host: fmi2Instantiate returned NULL\n");
        goto out;
    }
    fmi2Status s;
    if ((s = setup_experiment(c, 0, 0.0, 0.0, 0, 0.0)) != fmi2OK ||
        (s = enter_init(c)) != fmi2OK || ((s = exit_init(c)) != fmi2OK && s != fmi2Warning)) {
        fprintf(stderr, "fmu_host: initialisation failed (status %d)\n", (int)s);
        goto out;
    }
    fmi2ValueReference vr_w = (fmi2ValueReference)d->frequency, vr_k = (fmi2ValueReference)d->steps;
    double w = 0;
    int k = 0;
    if (get_real(c, &vr_w, 1, &w) != fmi2OK || get_integer(c, &vr_k, 1, &k) != fmi2OK || !(w > 0) ||
        k <= 0) {
        fprintf(stderr, "fmu_host: cannot read frequency and steps\n");
        goto out;
    }
    const double period = 2.0 * 3.14159265358979323846 / w, h = period / k;
    size_t n = d->n_outputs;
    values = malloc(n * sizeof *values);
    vrs = malloc(n * sizeof *vrs);
    if (!values || !vrs) goto out;
    for (size_t i = 0; i < n; i++) vrs[i] = d->outputs[i].vr;
    printf("period %.17g\nsteps %d\noutputs %zu\n", period, k, n);

    long total = steps_total >= 0 ? steps_total : periods * k, nonfinite = 0;
    if (rss_every > 0) printf("rss 0 %ld\n", rss_kib());
    double t0 = now_s();
    for (long i = 0; i < total; i++) {
        if (resolve_every > 0 && d->frequency_in >= 0 && i > 0 && i % resolve_every == 0) {
            fmi2ValueReference vr_in = (fmi2ValueReference)d->frequency_in;
            double w_in = (i / resolve_every) % 2 ? 1.001 * w : w;
            if (set_real(c, &vr_in, 1, &w_in) != fmi2OK) {
                fprintf(stderr, "fmu_host: fmi2SetReal(frequency_in) failed at step %ld\n", i);
                goto out;
            }
        }
        /* fmpy style: t = start + i*h (the FMU compares communication points with a tolerance). */
        if ((s = do_step(c, (double)i * h, h, 1)) != fmi2OK) {
            fprintf(stderr, "fmu_host: fmi2DoStep %ld failed (status %d)\n", i, (int)s);
            goto out;
        }
        if ((s = get_real(c, vrs, n, values)) != fmi2OK) {
            fprintf(stderr, "fmu_host: fmi2GetReal after step %ld failed (status %d)\n", i, (int)s);
            goto out;
        }
        for (size_t j = 0; j < n; j++)
            if (!isfinite(values[j])) nonfinite++;
        if (steps_total < 0 && (i + 1) % k == 0)
            for (size_t j = 0; j < n; j++)
                printf("output %s %.17g\n", d->outputs[j].name, values[j]);
        if (rss_every > 0 && (i + 1) % rss_every == 0) printf("rss %ld %ld\n", i + 1, rss_kib());
    }
    double elapsed = now_s() - t0;
    printf("elapsed_s %.6f\nsteps_per_s %.0f\nnonfinite %ld\n", elapsed,
           elapsed > 0 ? (double)total / elapsed : 0.0, nonfinite);
    if ((s = terminate(c)) != fmi2OK) {
        fprintf(stderr, "fmu_host: fmi2Terminate failed (status %d)\n", (int)s);
        goto out;
    }
    rc = nonfinite == 0 ? 0 : 1;
out:
    free_instance(c); /* NULL is allowed */
    free(values);
    free(vrs);
    free(d);
    dlclose(lib);
    return rc;
}
