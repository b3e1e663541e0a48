/* A real C, variadic fmi2CallbackLogger for the host harness (Rust cannot define variadic
 * functions on stable). It formats with the format it is given, as an importer does, and
 * forwards the result to a sink found through componentEnvironment. If an FMU passed its
 * message as the format, a "%s%n" inside it would read and write through garbage here. */
#include <stdarg.h>
#include <stdio.h>

typedef void (*sink_fn)(void *ctx, const char *instance, int status, const char *category,
                        const char *format, const char *message);
struct log_env {
    sink_fn sink;
    void *ctx;
};

void test_logger(void *env, const char *instance, int status, const char *category,
                 const char *format, ...) {
    char message[16384];
    va_list ap;
    va_start(ap, format);
    vsnprintf(message, sizeof message, format, ap);
    va_end(ap);
    struct log_env *e = env;
    if (e && e->sink) e->sink(e->ctx, instance, status, category, format, message);
}
