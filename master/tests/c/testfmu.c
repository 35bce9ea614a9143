/* A tiny FMI 2.0 co-simulation slave for the master's tests, compiled with gcc at test time.
 *
 * Real:    0 u (input)  1 y (output, y = x, dx/dt = k*u, explicit Euler over each step)
 *          2 k (parameter)  3 t_last (output: t+h of the last step)
 *          4 grid_error (output: max over all steps of |t - t_(n*m)| with the nanosecond grid
 *            t_j = (round(t0 1e9) + j round(base_step 1e9))/1e9, n the number of steps taken and
 *            m = round(h/base_step), and of |t - (t_prev + h_prev)|; exactly 0 on an exact,
 *            contiguous grid)
 *          5 base_step (parameter, 0 = no grid check)  6 y2 (output, y2 = k*u, feed-through)
 * Integer: 0 steps (output)  1 fail_at_step (parameter: fmi2DoStep returns fmi2Error at that
 *          step, -1 = never)  2 n_in (input)  3 n_out (output, n_out = n_in)
 *          4 terminate_at_step (parameter: fmi2DoStep returns fmi2Discard with fmi2Terminated
 *            = true at that step, ending the simulation early; -1 = never)
 * Boolean: 0 enabled (input: integrate only when true)  1 enabled_out (output)
 *
 * Defines: MODEL_GUID (checked in fmi2Instantiate), OMIT_CANCEL_STEP (leave out fmi2CancelStep
 * to test symbol checks), LOG_EVERY_STEP (log an info message in every step).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#ifndef MODEL_GUID
#define MODEL_GUID "{shipsim-test-fmu}"
#endif
#define EXPORT __attribute__((visibility("default")))

typedef struct {
    fmi2CallbackFunctions cb;
    char name[128];
    double r[7];
    int i[5];
    int terminated;
    double last_ok;
    int b[2];
    double t0, x;
    long n;
    int state; /* 0 instantiated, 1 init, 2 step, 3 terminated, 4 error */
} Inst;

#define LOG(c, st, ...) (c)->cb.logger((c)->cb.componentEnvironment, (c)->name, st, "logAll", __VA_ARGS__)

static void outputs(Inst *c) {
    c->r[1] = c->x;
    c->r[6] = c->r[2] * c->r[0];
    c->i[0] = (int)c->n;
    c->i[3] = c->i[2];
    c->b[1] = c->b[0];
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)c; (void)on; (void)n; (void)cat; return fmi2OK;
}
EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                                     const fmi2CallbackFunctions *f, fmi2Boolean vis, fmi2Boolean log) {
    (void)res; (void)vis; (void)log;
    if (!f || !f->logger) return NULL;
    if (type != fmi2CoSimulation) return NULL;
    if (!guid || strcmp(guid, MODEL_GUID) != 0) {
        f->logger(f->componentEnvironment, name, fmi2Error, "logStatusError", "Wrong GUID %s, expected %s.", guid ? guid : "(null)", MODEL_GUID);
        return NULL;
    }
    Inst *c = calloc(1, sizeof(Inst));
    c->cb = *f;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "");
    c->r[2] = 1.0;
    c->i[1] = -1;
    c->i[4] = -1;
    c->b[0] = 1;
    outputs(c);
    return c;
}
EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, fmi2Real stop) {
    (void)td; (void)tol; (void)sd; (void)stop;
    Inst *p = c;
    if (p->state != 0) { LOG(p, fmi2Error, "fmi2SetupExperiment: illegal call sequence"); return fmi2Error; }
    p->t0 = t0;
    p->r[3] = t0;
    return fmi2OK;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Inst *p = c;
    if (p->state != 0) { LOG(p, fmi2Error, "illegal call sequence"); return fmi2Error; }
    p->state = 1; return fmi2OK;
}
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Inst *p = c;
    if (p->state != 1) { LOG(p, fmi2Error, "illegal call sequence"); return fmi2Error; }
    p->state = 2; outputs(p); return fmi2OK;
}
EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    Inst *p = c;
    if (p->state != 2 && p->state != 1) { LOG(p, fmi2Error, "fmi2Terminate: illegal call sequence"); return fmi2Error; }
    p->state = 3; return fmi2OK;
}
EXPORT fmi2Status fmi2Reset(fmi2Component c) { (void)c; return fmi2Error; }

#define CHECK_VR(arr, n, max)                                                         \
    for (size_t j = 0; j < n; j++)                                                    \
        if (vr[j] >= max) { LOG(p, fmi2Error, "bad value reference %u", vr[j]); return fmi2Error; }

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    Inst *p = c; CHECK_VR(p->r, n, 7);
    if (p->state == 1) outputs(p);
    for (size_t j = 0; j < n; j++) v[j] = p->r[vr[j]];
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    Inst *p = c; CHECK_VR(p->i, n, 5);
    if (p->state == 1) outputs(p);
    for (size_t j = 0; j < n; j++) v[j] = p->i[vr[j]];
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    Inst *p = c; CHECK_VR(p->b, n, 2);
    if (p->state == 1) outputs(p);
    for (size_t j = 0; j < n; j++) v[j] = p->b[vr[j]];
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    Inst *p = c; (void)v; if (n) { LOG(p, fmi2Error, "no string variables (vr %u)", vr[0]); return fmi2Error; } return fmi2OK;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    Inst *p = c; CHECK_VR(p->r, n, 7);
    for (size_t j = 0; j < n; j++) p->r[vr[j]] = v[j];
    outputs(p);
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    Inst *p = c; CHECK_VR(p->i, n, 5);
    for (size_t j = 0; j < n; j++) p->i[vr[j]] = v[j];
    outputs(p);
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    Inst *p = c; CHECK_VR(p->b, n, 2);
    for (size_t j = 0; j < n; j++) p->b[vr[j]] = v[j];
    outputs(p);
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    Inst *p = c; (void)v; if (n) { LOG(p, fmi2Error, "no string variables (vr %u)", vr[0]); return fmi2Error; } return fmi2OK;
}
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { (void)c; (void)s; (void)n; return fmi2Error; }
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) { (void)c; (void)s; (void)b; (void)n; return fmi2Error; }
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) { (void)c; (void)s; (void)b; (void)n; return fmi2Error; }
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu, const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz; return fmi2Error;
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], const fmi2Real v[]) {
    (void)c; (void)vr; (void)n; (void)o; (void)v; return fmi2Error;
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], fmi2Real v[]) {
    (void)c; (void)vr; (void)n; (void)o; (void)v; return fmi2Error;
}
EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noprior) {
    (void)noprior;
    Inst *p = c;
    if (p->state != 2) { LOG(p, fmi2Error, "fmi2DoStep: illegal call sequence (state %d)", p->state); return fmi2Error; }
    if (p->n == p->i[1]) {
        LOG(p, fmi2Error, "fmi2DoStep: failing at step %d (t = %g) as requested by fail_at_step", p->i[1], t);
        p->state = 4;
        return fmi2Error;
    }
    if (p->n == p->i[4]) {
        LOG(p, fmi2Discard, "fmi2DoStep: the model ends the simulation at t = %g", t);
        p->terminated = 1;
        p->last_ok = t;
        return fmi2Discard;
    }
    if (p->r[5] > 0) {
        long m = lround(h / p->r[5]);
        long long j = (long long)p->n * m;
        double expected = (double)(llround(p->t0 * 1e9) + j * llround(p->r[5] * 1e9)) / 1e9;
        double err = fabs(t - expected);
        if (p->n > 0 && fabs(t - p->r[3]) > err) err = fabs(t - p->r[3]);
        if (err > p->r[4]) p->r[4] = err;
    }
#ifdef LOG_EVERY_STEP
    LOG(p, fmi2OK, "step %ld at t = %g", p->n, t);
#endif
    if (p->b[0]) p->x += h * p->r[2] * p->r[0];
    p->n += 1;
    p->r[3] = t + h;
    outputs(p);
    return fmi2OK;
}
#ifndef OMIT_CANCEL_STEP
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
#endif
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) { (void)c; (void)s; (void)v; return fmi2Error; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    Inst *p = c;
    if (s != fmi2LastSuccessfulTime) return fmi2Error;
    *v = p->last_ok;
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) { (void)c; (void)s; (void)v; return fmi2Error; }
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    Inst *p = c;
    if (s != fmi2Terminated) return fmi2Error;
    *v = p->terminated;
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) { (void)c; (void)s; (void)v; return fmi2Error; }
