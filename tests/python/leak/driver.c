/* Leak driver (issue 16): loads the FMU's shared library, runs a seeded
 * random sequence of FMI 2.0 calls on several instances — steps, setters,
 * FMU states got, set, serialized, deserialized and deliberately NOT freed —
 * then frees the instances. Run under valgrind memcheck by
 * tests/python/test_fmu_leaks.py, which requires 0 bytes definitely or
 * indirectly lost. Usage: driver LIB.so GUID RESOURCE_URI [STEPS] */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *C;
typedef void *S;
typedef int St;
typedef struct {
    void (*logger)(void *, const char *, St, const char *, const char *, ...);
    void *(*alloc)(size_t, size_t);
    void (*free)(void *);
    void *step_finished;
    void *env;
} Cb;

static void logger(void *e, const char *n, St s, const char *c, const char *m, ...) {
    (void)e; (void)n; (void)s; (void)c; (void)m;
}

static unsigned long long rng = 0x2545F4914F6CDD1DULL;
static unsigned rnd(unsigned n) {
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (unsigned)(rng % n);
}

#define F(name, ret, ...) typedef ret (*name##_t)(__VA_ARGS__); static name##_t name;
F(fmi2Instantiate, C, const char *, int, const char *, const char *, const Cb *, int, int)
F(fmi2FreeInstance, void, C)
F(fmi2SetupExperiment, St, C, int, double, double, int, double)
F(fmi2EnterInitializationMode, St, C)
F(fmi2ExitInitializationMode, St, C)
F(fmi2DoStep, St, C, double, double, int)
F(fmi2SetReal, St, C, const unsigned *, size_t, const double *)
F(fmi2GetReal, St, C, const unsigned *, size_t, double *)
F(fmi2GetFMUstate, St, C, S *)
F(fmi2SetFMUstate, St, C, S)
F(fmi2FreeFMUstate, St, C, S *)
F(fmi2SerializedFMUstateSize, St, C, S, size_t *)
F(fmi2SerializeFMUstate, St, C, S, char *, size_t)
F(fmi2DeSerializeFMUstate, St, C, const char *, size_t, S *)
F(fmi2Reset, St, C)
F(fmi2SetString, St, C, const unsigned *, size_t, const char **)
F(fmi2SetDebugLogging, St, C, int, size_t, const char **)

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: driver LIB GUID URI [STEPS]\n"); return 2; }
    int steps = argc > 4 ? atoi(argv[4]) : 2000;
    void *h = dlopen(argv[1], RTLD_NOW);
    if (!h) { fprintf(stderr, "%s\n", dlerror()); return 2; }
#define L(name) name = (name##_t)dlsym(h, #name); if (!name) { fprintf(stderr, "no " #name "\n"); return 2; }
    L(fmi2Instantiate) L(fmi2FreeInstance) L(fmi2SetupExperiment) L(fmi2EnterInitializationMode)
    L(fmi2ExitInitializationMode) L(fmi2DoStep) L(fmi2SetReal) L(fmi2GetReal) L(fmi2GetFMUstate)
    L(fmi2SetFMUstate) L(fmi2FreeFMUstate) L(fmi2SerializedFMUstateSize) L(fmi2SerializeFMUstate)
    L(fmi2DeSerializeFMUstate) L(fmi2Reset) L(fmi2SetString) L(fmi2SetDebugLogging)
    Cb cb = {logger, calloc, free, NULL, NULL};
    enum { N = 3 };
    C inst[N];
    double t[N];
    S kept[N][4];
    memset(kept, 0, sizeof kept);
    const char *kinds[] = {"steady", "relaxation", "lugre"};
    for (int i = 0; i < N; i++) {
        inst[i] = fmi2Instantiate("leak", 1, argv[2], argv[3], &cb, 0, 0);
        if (!inst[i]) { fprintf(stderr, "instantiate failed\n"); return 1; }
        unsigned vr_tr = 42; /* transient */
        fmi2SetString(inst[i], &vr_tr, 1, &kinds[i]);
        fmi2SetupExperiment(inst[i], 0, 0, 0.0, 0, 0);
        fmi2EnterInitializationMode(inst[i]);
        fmi2ExitInitializationMode(inst[i]);
        t[i] = 0.0;
    }
    const double vals[] = {0.0, 1.0, -3.0, 20.0, 1e300, -1e300, 4000.0, 150.0, 0.5};
    for (int k = 0; k < steps; k++) {
        int i = (int)rnd(N);
        switch (rnd(10)) {
        case 0: case 1: case 2: {
            if (fmi2DoStep(inst[i], t[i], 1e-3, 1) == 0) t[i] += 1e-3;
            break;
        }
        case 3: {
            unsigned vr = rnd(10);
            double x = vals[rnd(sizeof vals / sizeof *vals)];
            fmi2SetReal(inst[i], &vr, 1, &x);
            break;
        }
        case 4: {
            unsigned vrs[3] = {20, 21, 24};
            double out[3];
            fmi2GetReal(inst[i], vrs, 3, out);
            break;
        }
        case 5: {
            /* a state got and never freed by the "master" */
            int slot = (int)rnd(4);
            fmi2GetFMUstate(inst[i], &kept[i][slot]);
            break;
        }
        case 6: {
            S s = NULL;
            if (fmi2GetFMUstate(inst[i], &s) == 0) {
                size_t n = 0;
                fmi2SerializedFMUstateSize(inst[i], s, &n);
                char *buf = malloc(n ? n : 1);
                fmi2SerializeFMUstate(inst[i], s, buf, n);
                S d = NULL;
                fmi2DeSerializeFMUstate(inst[i], buf, n, &d);   /* d leaked to the instance */
                if (rnd(2)) fmi2FreeFMUstate(inst[i], &s);
                free(buf);
            }
            break;
        }
        case 7: {
            int slot = (int)rnd(4);
            if (kept[i][slot]) {
                if (rnd(2)) fmi2SetFMUstate(inst[i], kept[i][slot]);
                else fmi2FreeFMUstate(inst[i], &kept[i][slot]);
            }
            break;
        }
        case 8: {
            const char *cats[] = {"logEvents", "logStatusError"};
            fmi2SetDebugLogging(inst[i], (int)rnd(2), rnd(3), cats);
            break;
        }
        default: {
            if (rnd(20) == 0) {
                fmi2Reset(inst[i]);
                fmi2SetupExperiment(inst[i], 0, 0, 0.0, 0, 0);
                fmi2EnterInitializationMode(inst[i]);
                fmi2ExitInitializationMode(inst[i]);
                t[i] = 0.0;
            }
        }
        }
    }
    for (int i = 0; i < N; i++) fmi2FreeInstance(inst[i]);
    dlclose(h);
    printf("driver: %d calls done\n", steps);
    return 0;
}
