/* A MOCK of the PeriodicContact FMU (FMI 2.0 co-simulation), for testing the validation harness
 * only (fmpy / libcosimpy plumbing, names, time origin) while the real FMU does not exist. It
 * plays back a periodic table written by tools/mock_engine.py into resources/table.txt:
 *
 *   line 1: k T nreal nxv   (nxv: number of leading displacement/velocity columns)
 *   then k lines of nreal values: the Real outputs (value references 5 .. 5+nreal-1) at t_j = jT/k,
 *   then the scheme name
 *
 * At communication time t it outputs row round(t/T' k) mod k, T' = 2π/frequency, displacement and
 * velocity scaled by force_scale (right for linear scenes only). gap_offset is accepted and
 * ignored. NOT the engine: it solves nothing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define VR_FREQ 0
#define VR_SCALE 1
#define VR_GAPOFF 2
#define VR_STEPS 3
#define VR_SCHEME 4
#define VR_OUT0 5

typedef struct {
    int k, nreal, nxv;
    double T0, freq, scale, gapoff, time;
    double *table;
    char scheme[32];
    int initialized;
} Inst;

static int row(Inst *s) {
    double T = 2.0 * M_PI / s->freq;
    double u = s->time / T * s->k;
    long j = lround(u);
    j %= s->k;
    if (j < 0) j += s->k;
    return (int)j;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) { return fmi2OK; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean log) {
    if (!res) return NULL;
    const char *p = res;
    if (strncmp(p, "file:", 5) == 0) p += 5;
    while (p[0] == '/' && p[1] == '/') p++;
    char path[4096];
    snprintf(path, sizeof path, "%s/table.txt", p);
    FILE *f = fopen(path, "r");
    if (!f) return NULL;
    Inst *s = calloc(1, sizeof(Inst));
    int nxv = 0;
    if (fscanf(f, "%d %lf %d %d", &s->k, &s->T0, &s->nreal, &nxv) != 4) { fclose(f); free(s); return NULL; }
    s->nxv = nxv;
    s->table = calloc((size_t)s->k * s->nreal, sizeof(double));
    for (int i = 0; i < s->k * s->nreal; i++)
        if (fscanf(f, "%lf", &s->table[i]) != 1) { fclose(f); free(s->table); free(s); return NULL; }
    if (fscanf(f, "%31s", s->scheme) != 1) strcpy(s->scheme, "cds");
    fclose(f);
    s->freq = 2.0 * M_PI / s->T0;
    s->scale = 1.0;
    return s;
}

void fmi2FreeInstance(fmi2Component c) {
    Inst *s = c;
    if (!s) return;
    free(s->table);
    free(s);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, fmi2Real t1) {
    ((Inst *)c)->time = t0;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { ((Inst *)c)->initialized = 1; return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    Inst *s = c;
    int j = row(s);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FREQ) v[i] = s->freq;
        else if (vr[i] == VR_SCALE) v[i] = s->scale;
        else if (vr[i] == VR_GAPOFF) v[i] = s->gapoff;
        else if (vr[i] >= VR_OUT0 && vr[i] < VR_OUT0 + (unsigned)s->nreal) {
            int col = vr[i] - VR_OUT0;
            double val = s->table[(size_t)j * s->nreal + col];
            v[i] = col < s->nxv ? s->scale * val : val;
        } else return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    Inst *s = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_STEPS) v[i] = s->k;
        else if (vr[i] == (unsigned)(VR_OUT0 + s->nreal)) v[i] = 0; /* lcp.pivots */
        else return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    Inst *s = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_SCHEME) v[i] = s->scheme;
        else return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    Inst *s = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FREQ) s->freq = v[i];
        else if (vr[i] == VR_SCALE) s->scale = v[i];
        else if (vr[i] == VR_GAPOFF) s->gapoff = v[i];
        else return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    Inst *s = c;
    for (size_t i = 0; i < n; i++)
        if (!(vr[i] == VR_STEPS && v[i] == s->k && !s->initialized)) return fmi2Error;
    return fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    Inst *s = c;
    for (size_t i = 0; i < n; i++)
        if (!(vr[i] == VR_SCHEME && !s->initialized && strcmp(v[i], s->scheme) == 0)) return fmi2Error;
    return fmi2OK;
}
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *st) { return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate st) { return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *st) { return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate st, size_t *n) { return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate st, fmi2Byte b[], size_t n) { return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *st) { return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference k[], size_t nk, const fmi2Real dk[], fmi2Real du[]) { return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], const fmi2Real v[]) { return fmi2Error; }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], fmi2Real v[]) { return fmi2Error; }
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean nos) {
    ((Inst *)c)->time = t + h;
    return fmi2OK;
}
fmi2Status fmi2CancelStep(fmi2Component c) { return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) { return fmi2Error; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) { *v = ((Inst *)c)->time; return fmi2OK; }
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) { return fmi2Error; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) { *v = fmi2False; return fmi2OK; }
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) { return fmi2Error; }
