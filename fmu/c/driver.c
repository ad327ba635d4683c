/* A small FMI importer in C: loads the FMU's binary for one platform and
 * calls its FMI 2.0 or 3.0 co-simulation functions, as a tool would, so
 * that a binary can be run where it runs (the aarch64 one under
 * qemu-user, the Windows one under wine) and its outputs compared with the
 * host's (`cargo xtask fmu-check`, docs/fmu.md).
 *
 * Usage: driver BINARY RESOURCES_DIR TOKEN 2|3
 *
 * Runs the twin at rest at 30 C and 3 bar supply, then the oil at 50 C with
 * the supply ramped to 6 bar: 100 steps of 1 ms, 50 of 0.1 ms, 20 of 2.5 ms
 * and 30 of 1/3 ms, and prints one line per step,
 * `time,x,v,p_a,p_b,Q0,flags` with every number as C99's %a (exact hex),
 * then `driver: N steps, 0 failed` (exit 0) or the failing call (exit 1).
 * Written against the standard's function signatures (fmi2Functions.h,
 * fmi3Functions.h), declared here: no header is needed to build it.
 */
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library;
static library open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(library l, const char *name) { return (void *)GetProcAddress(l, name); }
#else
#include <dlfcn.h>
typedef void *library;
static library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(library l, const char *name) { return dlsym(l, name); }
#endif

/* Value references (fmu/src/variables.rs). */
enum { VR_TIME = 0, VR_T_OIL = 1, VR_P_SUPPLY = 2, VR_P_OUTLET = 3, VR_X = 10, VR_Q0 = 17, VR_FLAGS = 19 };

/* FMI 2.0 */
typedef void (*fmi2Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    fmi2Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free_memory)(void *);
    void (*step_finished)(void *, int);
    void *env;
} fmi2Callbacks;
typedef void *(*fmi2Instantiate_t)(const char *, int, const char *, const char *, const fmi2Callbacks *, int, int);
typedef int (*fmi2SetupExperiment_t)(void *, int, double, double, int, double);
typedef int (*fmi2Mode_t)(void *);
typedef int (*fmi2SetReal_t)(void *, const unsigned *, size_t, const double *);
typedef int (*fmi2GetReal_t)(void *, const unsigned *, size_t, double *);
typedef int (*fmi2GetInteger_t)(void *, const unsigned *, size_t, int *);
typedef int (*fmi2DoStep_t)(void *, double, double, int);
typedef void (*fmi2Free_t)(void *);

/* FMI 3.0 */
typedef void (*fmi3Log)(void *, int, const char *, const char *);
typedef void *(*fmi3Instantiate_t)(const char *, const char *, const char *, bool, bool, bool, bool, const unsigned *,
                                   size_t, void *, fmi3Log, void *);
typedef int (*fmi3EnterInit_t)(void *, bool, double, double, bool, double);
typedef int (*fmi3Mode_t)(void *);
typedef int (*fmi3SetFloat64_t)(void *, const unsigned *, size_t, const double *, size_t);
typedef int (*fmi3GetFloat64_t)(void *, const unsigned *, size_t, double *, size_t);
typedef int (*fmi3GetInt32_t)(void *, const unsigned *, size_t, int32_t *, size_t);
typedef int (*fmi3DoStep_t)(void *, double, double, bool, bool *, bool *, bool *, double *);
typedef void (*fmi3Free_t)(void *);

static void logger2(void *env, const char *name, int status, const char *category, const char *message, ...) {
    (void)env;
    (void)category;
    fprintf(stderr, "fmu %s (status %d): %s\n", name, status, message);
}

static void logger3(void *env, int status, const char *category, const char *message) {
    (void)env;
    (void)category;
    fprintf(stderr, "fmu (status %d): %s\n", status, message);
}

static library lib;

static void *need(const char *name) {
    void *f = symbol(lib, name);
    if (!f) {
        fprintf(stderr, "driver: the binary exports no %s\n", name);
        exit(1);
    }
    return f;
}

#define CHECK(call)                                                    \
    do {                                                               \
        int status_ = (call);                                          \
        if (status_ != 0) {                                            \
            fprintf(stderr, "driver: %s returned %d\n", #call, status_); \
            return 1;                                                  \
        }                                                              \
    } while (0)

int main(int argc, char **argv) {
    if (argc != 5 || (strcmp(argv[4], "2") != 0 && strcmp(argv[4], "3") != 0)) {
        fprintf(stderr, "usage: driver BINARY RESOURCES_DIR TOKEN 2|3\n");
        return 2;
    }
    lib = open_library(argv[1]);
    if (!lib) {
        fprintf(stderr, "driver: cannot load %s\n", argv[1]);
        return 1;
    }
    bool v3 = argv[4][0] == '3';
    const char *resources = argv[2], *token = argv[3];
    void *c;
    char uri[4096];
    fmi2Callbacks callbacks = {logger2, NULL, NULL, NULL, NULL};
    if (v3) {
        c = ((fmi3Instantiate_t)need("fmi3InstantiateCoSimulation"))("driver", token, resources, false, true, false,
                                                                      false, NULL, 0, NULL, logger3, NULL);
    } else {
        snprintf(uri, sizeof uri, "file:///%s", resources[0] == '/' ? resources + 1 : resources);
        c = ((fmi2Instantiate_t)need("fmi2Instantiate"))("driver", 1, token, uri, &callbacks, 0, 1);
    }
    if (!c) {
        fprintf(stderr, "driver: instantiation failed\n");
        return 1;
    }
    fmi2SetReal_t set2 = v3 ? NULL : (fmi2SetReal_t)need("fmi2SetReal");
    fmi2GetReal_t get2 = v3 ? NULL : (fmi2GetReal_t)need("fmi2GetReal");
    fmi3SetFloat64_t set3 = v3 ? (fmi3SetFloat64_t)need("fmi3SetFloat64") : NULL;
    fmi3GetFloat64_t get3 = v3 ? (fmi3GetFloat64_t)need("fmi3GetFloat64") : NULL;
    const unsigned inputs[3] = {VR_T_OIL, VR_P_SUPPLY, VR_P_OUTLET};
    double start[3] = {30.0, 3e5, 0.0};
    if (v3) {
        CHECK(set3(c, inputs, 3, start, 3));
        CHECK(((fmi3EnterInit_t)need("fmi3EnterInitializationMode"))(c, false, 0.0, 0.0, false, 0.0));
        CHECK(((fmi3Mode_t)need("fmi3ExitInitializationMode"))(c));
    } else {
        CHECK(set2(c, inputs, 3, start));
        CHECK(((fmi2SetupExperiment_t)need("fmi2SetupExperiment"))(c, 0, 0.0, 0.0, 0, 0.0));
        CHECK(((fmi2Mode_t)need("fmi2EnterInitializationMode"))(c));
        CHECK(((fmi2Mode_t)need("fmi2ExitInitializationMode"))(c));
    }
    const struct {
        int n;
        double h;
    } phases[4] = {{100, 1e-3}, {50, 1e-4}, {20, 2.5e-3}, {30, 1e-3 / 3.0}};
    const unsigned outputs[6] = {VR_X, VR_X + 1, VR_X + 2, VR_X + 3, VR_Q0, VR_FLAGS};
    double t = 0.0;
    int steps = 0;
    for (int p = 0; p < 4; p++) {
        for (int k = 0; k < phases[p].n; k++) {
            double h = phases[p].h;
            /* The supply ramps 3 -> 6 bar over 0.2 s, its value at the step's midpoint. */
            double mid = t + 0.5 * h;
            double supply = mid >= 0.2 ? 6e5 : 3e5 + 3e5 * mid / 0.2;
            double in[3] = {50.0, supply, 0.0};
            double out[5];
            int flags;
            if (v3) {
                bool event, terminate, early;
                double last;
                CHECK(set3(c, inputs, 3, in, 3));
                CHECK(((fmi3DoStep_t)need("fmi3DoStep"))(c, t, h, false, &event, &terminate, &early, &last));
                CHECK(get3(c, outputs, 5, out, 5));
                CHECK(((fmi3GetInt32_t)need("fmi3GetInt32"))(c, &outputs[5], 1, &flags, 1));
            } else {
                CHECK(set2(c, inputs, 3, in));
                CHECK(((fmi2DoStep_t)need("fmi2DoStep"))(c, t, h, 1));
                CHECK(get2(c, outputs, 5, out));
                CHECK(((fmi2GetInteger_t)need("fmi2GetInteger"))(c, &outputs[5], 1, &flags));
            }
            t += h;
            steps++;
            printf("%a,%a,%a,%a,%a,%a,%d\n", t, out[0], out[1], out[2], out[3], out[4], flags);
        }
    }
    if (v3) {
        ((fmi3Mode_t)need("fmi3Terminate"))(c);
        ((fmi3Free_t)need("fmi3FreeInstance"))(c);
    } else {
        ((fmi2Mode_t)need("fmi2Terminate"))(c);
        ((fmi2Free_t)need("fmi2FreeInstance"))(c);
    }
    printf("driver: %d steps, 0 failed\n", steps);
    return 0;
}
