/* Formats an FMI 2.0 log message (printf semantics, as the standard prescribes) and forwards it
 * to a non-variadic sink. The componentEnvironment the importer passes to fmi2Instantiate must
 * point to a `fmi2_log_target` (see fmi2::LogTarget in Rust). */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void (*fmi2_log_sink)(void *ctx, const char *instance, int status, const char *category,
                              const char *message);

typedef struct {
    fmi2_log_sink sink;
    void *ctx;
} fmi2_log_target;

void fmi2_logger_proxy(void *env, const char *instance, int status, const char *category,
                       const char *fmt, ...) {
    fmi2_log_target *target = (fmi2_log_target *)env;
    char stack_buf[1024];
    char *buf = stack_buf;
    va_list args;
    int n;
    if (target == NULL || target->sink == NULL) return;
    if (fmt == NULL) fmt = "";
    va_start(args, fmt);
    n = vsnprintf(stack_buf, sizeof stack_buf, fmt, args);
    va_end(args);
    if (n < 0) {
        buf = (char *)fmt; /* unformattable: pass the raw text on */
    } else if ((size_t)n >= sizeof stack_buf) {
        char *heap = (char *)malloc((size_t)n + 1);
        if (heap != NULL) {
            va_start(args, fmt);
            vsnprintf(heap, (size_t)n + 1, fmt, args);
            va_end(args);
            buf = heap;
        }
    }
    target->sink(target->ctx, instance ? instance : "", status, category ? category : "", buf);
    if (buf != stack_buf && buf != fmt) free(buf);
}
