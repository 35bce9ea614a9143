/* The C test FMU (testfmu.c, same variables and model description) with one misbehaviour,
 * chosen by a define, for the crash-isolation tests (tests/isolation.rs):
 *
 *   EVIL_SEGV        fmi2DoStep writes through a NULL pointer (SIGSEGV)
 *   EVIL_ABORT       fmi2DoStep calls abort() (SIGABRT)
 *   EVIL_EXIT=N      fmi2DoStep calls exit(N)
 *   EVIL_HANG        fmi2DoStep never returns
 *   EVIL_NAN         fmi2DoStep returns fmi2OK with y = NaN
 *   EVIL_INIT_FAIL   fmi2ExitInitializationMode returns fmi2Error
 *   EVIL_REJECT_NAN  fmi2SetReal returns fmi2Error for a non-finite value
 *   EVIL_LOAD_SEGV   the library's load-time initializer (a constructor) segfaults
 *
 * each at the step with index EVIL_AT_STEP (default 3: after three completed steps), and with
 * EVIL_IF_U_ABOVE=X only when the input u is above X (for campaigns that vary u). Every
 * variant also enforces the FMI 2.0 state machine on fmi2Terminate (sec. 4.2.4: not allowed in
 * Initialization Mode) by logging an error, as the project's FMUs do.
 */
#define fmi2DoStep testfmu_fmi2DoStep
#define fmi2Terminate testfmu_fmi2Terminate
#define fmi2ExitInitializationMode testfmu_fmi2ExitInitializationMode
#define fmi2SetReal testfmu_fmi2SetReal
#include "testfmu.c"
#undef fmi2DoStep
#undef fmi2Terminate
#undef fmi2ExitInitializationMode
#undef fmi2SetReal
#include <unistd.h>

#ifndef EVIL_AT_STEP
#define EVIL_AT_STEP 3
#endif

#ifdef EVIL_LOAD_SEGV
/* Through a volatile pointer: the compiler drops a constructor whose store it can prove is to
 * NULL (undefined), and raise(SIGSEGV) would return from Rust's stack-overflow handler. */
static int *volatile evil_null = 0;
__attribute__((constructor)) static void evil_load(void) {
    *evil_null = 1;
}
#endif

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noprior) {
    Inst *p = c;
#ifndef EVIL_IF_U_ABOVE
#define EVIL_IF_U_ABOVE (-HUGE_VAL)
#endif
    if (p->state == 2 && p->n == EVIL_AT_STEP && p->r[0] > EVIL_IF_U_ABOVE) {
        LOG(p, fmi2Warning, "misbehaving now at t = %g", t);
#if defined(EVIL_SEGV)
        *(volatile int *)0 = 1;
#elif defined(EVIL_ABORT)
        abort();
#elif defined(EVIL_EXIT)
        exit(EVIL_EXIT);
#elif defined(EVIL_HANG)
        for (;;) sleep(1);
#elif defined(EVIL_NAN)
        fmi2Status s = testfmu_fmi2DoStep(c, t, h, noprior);
        p->x = NAN;
        outputs(p);
        return s;
#endif
    }
    return testfmu_fmi2DoStep(c, t, h, noprior);
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    Inst *p = c;
    if (p->state == 1) {
        LOG(p, fmi2Error, "fmi2Terminate is not allowed in state InitializationMode");
        return fmi2Error;
    }
    return testfmu_fmi2Terminate(c);
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
#ifdef EVIL_INIT_FAIL
    Inst *p = c;
    LOG(p, fmi2Error, "fmi2ExitInitializationMode: failing on purpose");
    return fmi2Error;
#else
    return testfmu_fmi2ExitInitializationMode(c);
#endif
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
#ifdef EVIL_REJECT_NAN
    Inst *p = c;
    for (size_t j = 0; j < n; j++)
        if (!isfinite(v[j])) {
            LOG(p, fmi2Error, "fmi2SetReal: value reference %u: %g is not finite", vr[j], v[j]);
            return fmi2Error;
        }
#endif
    return testfmu_fmi2SetReal(c, vr, n, v);
}
