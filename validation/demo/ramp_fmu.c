/* FrequencyRamp: a minimal FMI 2.0 co-simulation SOURCE component for the drop-in demo.
 *
 * It has no input. Its single output `frequency` [rad/s] is a linear run-up
 *
 *     frequency(t) = f_start                                   for t <= t_start
 *                  = f_start + (f_end - f_start)(t - t_start)/(t_end - t_start)
 *                  = f_end                                     for t >= t_end
 *
 * and its parameters f_start, f_end, t_start, t_end are fixed (set before initialisation).
 * It stands for "another component" of a system simulation (a motor speed controller, a test
 * rig schedule, ...) and knows nothing about periodic-contact. Built by build_ramp.py with gcc
 * against fmpy's FMI 2.0 headers; all 34 FMI 2 CS functions are exported (FMIL loads them all).
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define GUID "{8c4e3d7a-5b1f-4c2e-9a6d-0d3e5f7a9b10}"

enum { VR_F_START = 0, VR_F_END, VR_T_START, VR_T_END, VR_FREQUENCY, NVR };

typedef struct {
    double v[NVR];
    double time;
    int initialized;
    fmi2CallbackFunctions cb;
    char name[64];
} Ramp;

static void log_error(Ramp *r, const char *msg) {
    if (r && r->cb.logger) r->cb.logger(r->cb.componentEnvironment, r->name, fmi2Error, "logStatusError", "%s", msg);
}

static double ramp_value(const Ramp *r, double t) {
    double f0 = r->v[VR_F_START], f1 = r->v[VR_F_END], t0 = r->v[VR_T_START], t1 = r->v[VR_T_END];
    if (t <= t0 || t1 <= t0) return t <= t0 ? f0 : f1;
    if (t >= t1) return f1;
    return f0 + (f1 - f0) * (t - t0) / (t1 - t0);
}

static void update(Ramp *r) { r->v[VR_FREQUENCY] = ramp_value(r, r->time); }

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)on; (void)n; (void)cat;
    return c ? fmi2OK : fmi2Error;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean log) {
    (void)res; (void)visible; (void)log;
    if (!cb) return NULL;
    Ramp tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *cb;
    strncpy(tmp.name, name ? name : "ramp", sizeof tmp.name - 1);
    if (type != fmi2CoSimulation) { log_error(&tmp, "FrequencyRamp supports co-simulation only"); return NULL; }
    if (!guid || strcmp(guid, GUID) != 0) { log_error(&tmp, "wrong GUID"); return NULL; }
    Ramp *r = calloc(1, sizeof(Ramp));
    if (!r) return NULL;
    *r = tmp;
    r->v[VR_F_START] = 1.0;
    r->v[VR_F_END] = 2.0;
    r->v[VR_T_START] = 0.0;
    r->v[VR_T_END] = 1.0;
    update(r);
    return r;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, fmi2Real t1) {
    (void)td; (void)tol; (void)sd; (void)t1;
    if (!c) return fmi2Error;
    ((Ramp *)c)->time = t0;
    update(c);
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) { if (!c) return fmi2Error; update(c); return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    if (!c) return fmi2Error;
    ((Ramp *)c)->initialized = 1;
    update(c);
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) { return c ? fmi2OK : fmi2Error; }
fmi2Status fmi2Reset(fmi2Component c) {
    if (!c) return fmi2Error;
    Ramp *r = c;
    r->time = 0.0;
    r->initialized = 0;
    r->v[VR_F_START] = 1.0; r->v[VR_F_END] = 2.0; r->v[VR_T_START] = 0.0; r->v[VR_T_END] = 1.0;
    update(r);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    if (!c || (n && (!vr || !value))) return fmi2Error;
    Ramp *r = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= NVR) { log_error(r, "unknown value reference"); return fmi2Error; }
        value[i] = r->v[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    if (!c || (n && (!vr || !value))) return fmi2Error;
    Ramp *r = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= VR_FREQUENCY) { log_error(r, "only the parameters f_start, f_end, t_start, t_end can be set"); return fmi2Error; }
        if (r->initialized) { log_error(r, "the parameters are fixed after initialisation"); return fmi2Error; }
        r->v[vr[i]] = value[i];
    }
    update(r);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) { (void)vr; (void)v; return c && n == 0 ? fmi2OK : fmi2Error; }

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)s; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { (void)s; (void)n; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) { (void)s; (void)b; (void)n; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) { (void)b; (void)n; (void)s; log_error(c, "no FMU state"); return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu, const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dv[], fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    log_error(c, "no directional derivatives");
    return fmi2Error;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], const fmi2Real v[]) {
    (void)vr; (void)o; (void)v; return c && n == 0 ? fmi2OK : fmi2Error;
}
/* order 1 of the output: the slope of the ramp */
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], fmi2Real v[]) {
    if (!c || (n && (!vr || !o || !v))) return fmi2Error;
    Ramp *r = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_FREQUENCY) return fmi2Error;
        double t0 = r->v[VR_T_START], t1 = r->v[VR_T_END];
        int inside = r->time >= t0 && r->time < t1 && t1 > t0;
        v[i] = (o[i] == 1 && inside) ? (r->v[VR_F_END] - r->v[VR_F_START]) / (t1 - t0) : 0.0;
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)noSetPrior;
    if (!c) return fmi2Error;
    Ramp *r = c;
    if (!r->initialized) { log_error(r, "fmi2DoStep before initialisation"); return fmi2Error; }
    if (h < 0) { log_error(r, "negative step"); return fmi2Error; }
    r->time = t + h;
    update(r);
    return fmi2OK;
}
fmi2Status fmi2CancelStep(fmi2Component c) { return c ? fmi2OK : fmi2Error; }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) { (void)s; (void)v; return c ? fmi2Discard : fmi2Error; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    if (!c || !v) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) { *v = ((Ramp *)c)->time; return fmi2OK; }
    return fmi2Discard;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) { (void)s; (void)v; return c ? fmi2Discard : fmi2Error; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    if (!c || !v) return fmi2Error;
    if (s == fmi2Terminated) { *v = fmi2False; return fmi2OK; }
    return fmi2Discard;
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) { (void)s; (void)v; return c ? fmi2Discard : fmi2Error; }
