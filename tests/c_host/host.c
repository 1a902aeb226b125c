/* A minimal FMI 2.0 or 3.0 co-simulation host, for tests/test_fmu_hosts.py and tests/test_standalone.py.
 *
 *   host FMU_DIR MODEL_IDENTIFIER GUID SCENARIO VR... [CYCLES]
 *
 * Compiled as is it is an FMI 2.0 host; with -DFMI3 an FMI 3.0 host (GUID is then the
 * instantiation token, VR the Float64 scalars' value references). Cross-compiled with mingw-w64
 * it is a Windows host of the FMU's win64 binary (LoadLibrary; FMU_DIR a Windows path). With tests/c_host/start.c
 * and -nostartfiles it starts on any x86-64 glibc (see there).
 *
 * FMU_DIR is the unzipped FMU; VR are the value references of the inputs
 * Fx Fy Fz Mx My psi omega followed by those of the outputs to print. The binary is
 * loaded with dlopen(RTLD_NOW | RTLD_LOCAL): no preload, nothing global. Lines printed:
 *
 *   <label> <step> <output values, %.17g>     outputs after a step
 *   status <label> <step> <doStep status> <terminated> <lastSuccessfulTime>
 *   log <status> <category> <message>         the FMU's log (logging on)
 *   error <text>                              a failed call (exit status 1)
 *
 * Scenarios: basic (steps, state get/set/serialize, free, dlclose and reload), two (two
 * instances interleaved), nan (a NaN input at step 3, refused, the step retried with valid inputs,
 * then valid steps, beside an undisturbed instance), stress (CYCLES x: load, two instances, a refused step, free, dlclose), bench
 * (FMI 2.0: --inputs FILE, 7 input values a line and step, --integer VR VALUE parameters;
 * prints "instantiate <s>" for loading, instantiation and initialisation, then "step <k> <s>"
 * for each set-inputs, doStep, get-outputs, then "rss <kB> <kB> <kB>": the resident set (VmRSS) before
 * loading, after the initialisation and after the steps: python -m benchmarks fmu_variants).
 */
#ifdef _WIN32
/* Windows (cross-compiled with mingw-w64, tests/test_win64.py): LoadLibrary for dlopen */
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <stdio.h>
#define RTLD_NOW 0
#define RTLD_LOCAL 0
#define dlopen(path, flags) ((void *)LoadLibraryExA((path), NULL, LOAD_WITH_ALTERED_SEARCH_PATH))
#define dlsym(handle, name) ((void *)GetProcAddress((HMODULE)(handle), (name)))
#define dlclose(handle) (FreeLibrary((HMODULE)(handle)) ? 0 : -1)
static const char *dlerror(void)
{
    static char text[64];
    snprintf(text, sizeof text, "Windows error %lu", (unsigned long)GetLastError());
    return text;
}
#ifndef PATH_MAX
#define PATH_MAX 4096
#endif
#define BINARY_SUFFIX ".dll"
#else
#include <dlfcn.h>
#define BINARY_SUFFIX ".so"
#endif
#include <limits.h>
#include <stdbool.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *fmi2Component;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status; /* 0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal (FMI 3.0: the same numbers) */

#ifndef FMI3
#ifdef _WIN32
#define PLATFORM "win64"
#else
#define PLATFORM "linux64"
#endif
typedef struct {
    void (*logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

typedef struct {
    void *handle;
    fmi2Component (*instantiate)(const char *, int, const char *, const char *, const fmi2CallbackFunctions *, int, int);
    void (*freeInstance)(fmi2Component);
    fmi2Status (*setup)(fmi2Component, int, double, double, int, double);
    fmi2Status (*enterInit)(fmi2Component);
    fmi2Status (*exitInit)(fmi2Component);
    fmi2Status (*terminate)(fmi2Component);
    fmi2Status (*setReal)(fmi2Component, const fmi2ValueReference *, size_t, const double *);
    fmi2Status (*getReal)(fmi2Component, const fmi2ValueReference *, size_t, double *);
    fmi2Status (*doStep)(fmi2Component, double, double, int);
    fmi2Status (*getState)(fmi2Component, fmi2FMUstate *);
    fmi2Status (*setState)(fmi2Component, fmi2FMUstate);
    fmi2Status (*freeState)(fmi2Component, fmi2FMUstate *);
    fmi2Status (*stateSize)(fmi2Component, fmi2FMUstate, size_t *);
    fmi2Status (*serialize)(fmi2Component, fmi2FMUstate, char *, size_t);
    fmi2Status (*deserialize)(fmi2Component, const char *, size_t, fmi2FMUstate *);
    fmi2Status (*getBooleanStatus)(fmi2Component, int, int *);
    fmi2Status (*getRealStatus)(fmi2Component, int, double *);
} Fmu;
#else
#ifdef _WIN32
#define PLATFORM "x86_64-windows"
#else
#define PLATFORM "x86_64-linux"
#endif
typedef struct {
    void *handle;
    fmi2Component (*instantiate)(const char *, const char *, const char *, bool, bool, bool, bool,
                                 const fmi2ValueReference *, size_t, void *,
                                 void (*)(void *, fmi2Status, const char *, const char *), void *);
    void (*freeInstance)(fmi2Component);
    fmi2Status (*enterInit)(fmi2Component, bool, double, double, bool, double);
    fmi2Status (*exitInit)(fmi2Component);
    fmi2Status (*terminate)(fmi2Component);
    fmi2Status (*setFloat64)(fmi2Component, const fmi2ValueReference *, size_t, const double *, size_t);
    fmi2Status (*getFloat64)(fmi2Component, const fmi2ValueReference *, size_t, double *, size_t);
    fmi2Status (*doStep3)(fmi2Component, double, double, bool, bool *, bool *, bool *, double *);
    fmi2Status (*getState)(fmi2Component, fmi2FMUstate *);
    fmi2Status (*setState)(fmi2Component, fmi2FMUstate);
    fmi2Status (*freeState)(fmi2Component, fmi2FMUstate *);
    fmi2Status (*stateSize)(fmi2Component, fmi2FMUstate, size_t *);
    fmi2Status (*serialize)(fmi2Component, fmi2FMUstate, char *, size_t);
    fmi2Status (*deserialize)(fmi2Component, const char *, size_t, fmi2FMUstate *);
    bool terminated;        /* FMI 3.0 has no status functions: what the last fmi3DoStep said */
    double last_successful;
} Fmu;
#endif

static char binary[PATH_MAX], resources[PATH_MAX + 16], guid[256];
static fmi2ValueReference inputs[7], outputs[64];
static size_t n_outputs;
static const double H = 0.01;

static void logger(void *env, const char *name, fmi2Status status, const char *category, const char *message, ...)
{
    (void)env;
    (void)name;
    char text[8192];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    for (char *p = text; *p; p++)  /* one line per message */
        if (*p == '\n')
            *p = '|';
    printf("log %d %s %s\n", status, category ? category : "-", text);
    fflush(stdout);
}

#ifndef FMI3
static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
#else
static void logger3(void *env, fmi2Status status, const char *category, const char *message)
{
    logger(env, NULL, status, category, "%s", message);
}
#endif

static void fail(const char *what)
{
    printf("error %s\n", what);
    fflush(stdout);
    exit(1);
}

#define CHECK(call)                        \
    do {                                   \
        if ((call) != 0)                   \
            fail(#call);                   \
    } while (0)

static void *symbol(void *handle, const char *name)
{
    void *f = dlsym(handle, name);
    if (!f)
        fail(name);
    return f;
}

static void load(Fmu *fmu)
{
    memset(fmu, 0, sizeof *fmu);
    fmu->handle = dlopen(binary, RTLD_NOW | RTLD_LOCAL);
    if (!fmu->handle) {
        printf("error dlopen: %s\n", dlerror());
        exit(1);
    }
#ifndef FMI3
    *(void **)&fmu->instantiate = symbol(fmu->handle, "fmi2Instantiate");
    *(void **)&fmu->freeInstance = symbol(fmu->handle, "fmi2FreeInstance");
    *(void **)&fmu->setup = symbol(fmu->handle, "fmi2SetupExperiment");
    *(void **)&fmu->enterInit = symbol(fmu->handle, "fmi2EnterInitializationMode");
    *(void **)&fmu->exitInit = symbol(fmu->handle, "fmi2ExitInitializationMode");
    *(void **)&fmu->terminate = symbol(fmu->handle, "fmi2Terminate");
    *(void **)&fmu->setReal = symbol(fmu->handle, "fmi2SetReal");
    *(void **)&fmu->getReal = symbol(fmu->handle, "fmi2GetReal");
    *(void **)&fmu->doStep = symbol(fmu->handle, "fmi2DoStep");
    *(void **)&fmu->getState = symbol(fmu->handle, "fmi2GetFMUstate");
    *(void **)&fmu->setState = symbol(fmu->handle, "fmi2SetFMUstate");
    *(void **)&fmu->freeState = symbol(fmu->handle, "fmi2FreeFMUstate");
    *(void **)&fmu->stateSize = symbol(fmu->handle, "fmi2SerializedFMUstateSize");
    *(void **)&fmu->serialize = symbol(fmu->handle, "fmi2SerializeFMUstate");
    *(void **)&fmu->deserialize = symbol(fmu->handle, "fmi2DeSerializeFMUstate");
    *(void **)&fmu->getBooleanStatus = symbol(fmu->handle, "fmi2GetBooleanStatus");
    *(void **)&fmu->getRealStatus = symbol(fmu->handle, "fmi2GetRealStatus");
#else
    *(void **)&fmu->instantiate = symbol(fmu->handle, "fmi3InstantiateCoSimulation");
    *(void **)&fmu->freeInstance = symbol(fmu->handle, "fmi3FreeInstance");
    *(void **)&fmu->enterInit = symbol(fmu->handle, "fmi3EnterInitializationMode");
    *(void **)&fmu->exitInit = symbol(fmu->handle, "fmi3ExitInitializationMode");
    *(void **)&fmu->terminate = symbol(fmu->handle, "fmi3Terminate");
    *(void **)&fmu->setFloat64 = symbol(fmu->handle, "fmi3SetFloat64");
    *(void **)&fmu->getFloat64 = symbol(fmu->handle, "fmi3GetFloat64");
    *(void **)&fmu->doStep3 = symbol(fmu->handle, "fmi3DoStep");
    *(void **)&fmu->getState = symbol(fmu->handle, "fmi3GetFMUState");
    *(void **)&fmu->setState = symbol(fmu->handle, "fmi3SetFMUState");
    *(void **)&fmu->freeState = symbol(fmu->handle, "fmi3FreeFMUState");
    *(void **)&fmu->stateSize = symbol(fmu->handle, "fmi3SerializedFMUStateSize");
    *(void **)&fmu->serialize = symbol(fmu->handle, "fmi3SerializeFMUState");
    *(void **)&fmu->deserialize = symbol(fmu->handle, "fmi3DeserializeFMUState");
#endif
}

/* The calls that differ between FMI 2.0 and 3.0, in one form. */
static fmi2Component instantiate(Fmu *fmu, const char *name)
{
#ifndef FMI3
    return fmu->instantiate(name, 1 /* co-simulation */, guid, resources, &callbacks, 0, 1);
#else
    return fmu->instantiate(name, guid, resources, false, true, false, false, NULL, 0, NULL, logger3, NULL);
#endif
}

static int initialize(Fmu *fmu, fmi2Component c)
{
#ifndef FMI3
    return fmu->setup(c, 0, 0.0, 0.0, 0, 0.0) || fmu->enterInit(c) || fmu->exitInit(c);
#else
    return fmu->enterInit(c, false, 0.0, 0.0, false, 0.0) || fmu->exitInit(c);
#endif
}

static fmi2Status set_real(Fmu *fmu, fmi2Component c, const fmi2ValueReference *vr, size_t n, const double *v)
{
#ifndef FMI3
    return fmu->setReal(c, vr, n, v);
#else
    return fmu->setFloat64(c, vr, n, v, n);
#endif
}

static fmi2Status get_real(Fmu *fmu, fmi2Component c, const fmi2ValueReference *vr, size_t n, double *v)
{
#ifndef FMI3
    return fmu->getReal(c, vr, n, v);
#else
    return fmu->getFloat64(c, vr, n, v, n);
#endif
}

static fmi2Status do_step(Fmu *fmu, fmi2Component c, double t, double h)
{
#ifndef FMI3
    return fmu->doStep(c, t, h, 1);
#else
    bool event = false, early = false;
    return fmu->doStep3(c, t, h, true, &event, &fmu->terminated, &early, &fmu->last_successful);
#endif
}

/* fmi2Terminated and fmi2LastSuccessfulTime; FMI 3.0: as the last fmi3DoStep returned them */
static void step_status(Fmu *fmu, fmi2Component c, int *terminated, double *last)
{
#ifndef FMI3
    CHECK(fmu->getBooleanStatus(c, 3 /* fmi2Terminated */, terminated));
    CHECK(fmu->getRealStatus(c, 2 /* fmi2LastSuccessfulTime */, last));
#else
    (void)c;
    *terminated = fmu->terminated;
    *last = fmu->last_successful;
#endif
}

static void unload(Fmu *fmu)
{
    if (dlclose(fmu->handle) != 0)
        fail("dlclose");
}

static fmi2Component start(Fmu *fmu, const char *name)
{
    fmi2Component c = instantiate(fmu, name);
    if (!c)
        fail("fmi2Instantiate");
    CHECK(initialize(fmu, c));
    return c;
}

static void stop(Fmu *fmu, fmi2Component c)
{
    CHECK(fmu->terminate(c));
    fmu->freeInstance(c);
}

/* inputs of step k: a slow load ramp and rotation; scale multiplies the loads */
static void set_inputs(Fmu *fmu, fmi2Component c, int k, double scale, int nan_fz)
{
    double u[7] = {8e3 * scale, -3e3 * scale, (3e4 + 1e3 * k) * scale, 1.5e3 * scale, -2.5e3 * scale,
                   0.4 + 0.01 * k, 0.05};
    if (nan_fz)
        u[2] = NAN;
    CHECK(set_real(fmu, c, inputs, 7, u));
}

static void print_outputs(Fmu *fmu, fmi2Component c, const char *label, int k)
{
    double y[64];
    CHECK(get_real(fmu, c, outputs, n_outputs, y));
    printf("%s %d", label, k);
    for (size_t i = 0; i < n_outputs; i++)
        printf(" %.17g", y[i]);
    printf("\n");
    fflush(stdout);
}

static fmi2Status step(Fmu *fmu, fmi2Component c, int k, double scale, int nan_fz)
{
    set_inputs(fmu, c, k, scale, nan_fz);
    return do_step(fmu, c, k * H, H);
}

static void step_ok(Fmu *fmu, fmi2Component c, const char *label, int k, double scale)
{
    if (step(fmu, c, k, scale, 0) != 0)
        fail("fmi2DoStep");
    print_outputs(fmu, c, label, k);
}

static void print_status(Fmu *fmu, fmi2Component c, const char *label, int k, fmi2Status status)
{
    int terminated = -1;
    double last = NAN;
    step_status(fmu, c, &terminated, &last);
    printf("status %s %d %d %d %.17g\n", label, k, status, terminated, last);
    fflush(stdout);
}

static void basic(void)
{
    Fmu fmu;
    load(&fmu);
    fmi2Component c = start(&fmu, "basic");
    for (int k = 0; k < 3; k++)
        step_ok(&fmu, c, "run", k, 1.0);
    fmi2FMUstate state = NULL;
    CHECK(fmu.getState(c, &state));
    size_t size = 0;
    CHECK(fmu.stateSize(c, state, &size));
    char *bytes = malloc(size);
    CHECK(fmu.serialize(c, state, bytes, size));
    for (int k = 3; k < 6; k++)
        step_ok(&fmu, c, "run", k, 1.0);
    CHECK(fmu.setState(c, state));
    for (int k = 3; k < 6; k++)
        step_ok(&fmu, c, "replay", k, 1.0);
    fmi2FMUstate restored = NULL;
    CHECK(fmu.deserialize(c, bytes, size, &restored));
    CHECK(fmu.setState(c, restored));
    for (int k = 3; k < 6; k++)
        step_ok(&fmu, c, "deserialized", k, 1.0);
    CHECK(fmu.freeState(c, &restored));
    CHECK(fmu.freeState(c, &state));
    free(bytes);
    stop(&fmu, c);
    unload(&fmu);
    /* free and reload: a new instance of the reloaded binary starts afresh */
    load(&fmu);
    c = start(&fmu, "reloaded");
    for (int k = 0; k < 6; k++)
        step_ok(&fmu, c, "reload", k, 1.0);
    stop(&fmu, c);
    unload(&fmu);
}

static void two(void)
{
    Fmu fmu;
    load(&fmu);
    fmi2Component a = start(&fmu, "a"), b = start(&fmu, "b");
    for (int k = 0; k < 6; k++) {
        step_ok(&fmu, a, "a", k, 1.0);
        step_ok(&fmu, b, "b", k, 2.0);
    }
    stop(&fmu, a);
    stop(&fmu, b);
    unload(&fmu);
}

static void nan_step(void)
{
    Fmu fmu;
    load(&fmu);
    fmi2Component undisturbed = start(&fmu, "undisturbed"), disturbed = start(&fmu, "disturbed");
    for (int k = 0; k < 8; k++) {
        if (k == 3) {  /* the disturbed instance gets a NaN, refused; it retries the step with valid inputs */
            fmi2Status status = step(&fmu, disturbed, k, 1.0, 1);
            print_status(&fmu, disturbed, "disturbed", k, status);
            print_outputs(&fmu, disturbed, "after_refusal", k);
        }
        step_ok(&fmu, undisturbed, "undisturbed", k, 1.0);
        step_ok(&fmu, disturbed, "disturbed", k, 1.0);
    }
    print_status(&fmu, disturbed, "disturbed", 8, 0);
    stop(&fmu, undisturbed);
    stop(&fmu, disturbed);
    unload(&fmu);
}

static void stress(int cycles)
{
    for (int cycle = 0; cycle < cycles; cycle++) {
        Fmu fmu;
        load(&fmu);
        fmi2Component a = start(&fmu, "a"), b = start(&fmu, "b");
        for (int k = 0; k < 3; k++) {
            if (step(&fmu, a, k, 1.0, 0) != 0 || step(&fmu, b, k, 2.0, 0) != 0)
                fail("fmi2DoStep");
        }
        if (step(&fmu, b, 3, 1.0, 1) != 2)  /* refused, then freed right away */
            fail("NaN step not discarded");
        print_outputs(&fmu, a, "cycle", cycle);
        stop(&fmu, a);
        fmu.freeInstance(b);
        unload(&fmu);
    }
}

#ifndef FMI3
static double now(void)
{
#ifdef _WIN32
    LARGE_INTEGER count, frequency;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&frequency);
    return (double)count.QuadPart / (double)frequency.QuadPart;
#endif
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* the process's resident set in kB (VmRSS of /proc/self/status), -1 where there is none (Windows) */
static long resident_kb(void)
{
    long kb = -1;
#ifndef _WIN32
    char line[256];
    FILE *status = fopen("/proc/self/status", "r");
    if (!status)
        return -1;
    while (fgets(line, sizeof line, status))
        if (!strncmp(line, "VmRSS:", 6)) {
            kb = strtol(line + 6, NULL, 10);
            break;
        }
    fclose(status);
#endif
    return kb;
}

static void bench(const char *input_file, const fmi2ValueReference *int_vrs, const int *int_values, size_t n_ints)
{
    FILE *fh = fopen(input_file, "r");
    if (!fh)
        fail("cannot open the inputs file");
    long rss_before = resident_kb();
    double start = now();
    Fmu fmu;
    load(&fmu);
    fmi2Component c = instantiate(&fmu, "bench");
    if (!c)
        fail("fmi2Instantiate");
    fmi2Status (*set_integer)(fmi2Component, const fmi2ValueReference *, size_t, const int *) =
        (fmi2Status(*)(fmi2Component, const fmi2ValueReference *, size_t, const int *))symbol(fmu.handle, "fmi2SetInteger");
    if (n_ints)
        CHECK(set_integer(c, int_vrs, n_ints, int_values));
    CHECK(initialize(&fmu, c));
    printf("instantiate %.9f\n", now() - start);
    long rss_instantiated = resident_kb();
    double u[7], y[64];
    for (int k = 0; fscanf(fh, "%lf %lf %lf %lf %lf %lf %lf", &u[0], &u[1], &u[2], &u[3], &u[4], &u[5], &u[6]) == 7; k++) {
        double t0 = now();
        CHECK(set_real(&fmu, c, inputs, 7, u));
        if (do_step(&fmu, c, k * H, H) != 0)
            fail("fmi2DoStep");
        CHECK(get_real(&fmu, c, outputs, n_outputs, y));
        printf("step %d %.9f\n", k, now() - t0);
    }
    fclose(fh);
    printf("rss %ld %ld %ld\n", rss_before, rss_instantiated, resident_kb());
    print_outputs(&fmu, c, "final", 0);
    stop(&fmu, c);
}
#endif

int main(int argc, char **argv)
{
    if (argc < 6 + 7) {
        fprintf(stderr, "usage: host FMU_DIR MODEL_IDENTIFIER GUID SCENARIO VR_INPUTS(7) VR_OUTPUTS... [--cycles N]\n");
        return 2;
    }
    snprintf(binary, sizeof binary, "%s/binaries/" PLATFORM "/%s" BINARY_SUFFIX, argv[1], argv[2]);
#if defined(_WIN32) && !defined(FMI3)
    {   /* FMI 2.0 on Windows: file:///C:/folder/resources */
        char uri_path[PATH_MAX];
        snprintf(uri_path, sizeof uri_path, "%s", argv[1]);
        for (char *p = uri_path; *p; p++)
            if (*p == '\\')
                *p = '/';
        snprintf(resources, sizeof resources, "file:///%s/resources", uri_path);
    }
#elif !defined(FMI3)
    snprintf(resources, sizeof resources, "file://%s/resources", argv[1]);
#else
    snprintf(resources, sizeof resources, "%s/resources/", argv[1]);  /* FMI 3.0: a path, not a URI */
#endif
    snprintf(guid, sizeof guid, "%s", argv[3]);
    const char *scenario = argv[4];
    int cycles = 3;
    const char *input_file = NULL;
    fmi2ValueReference int_vrs[16];
    int int_values[16];
    size_t n_ints = 0;
#ifdef FMI3
    (void)int_vrs, (void)int_values;    /* the bench scenario is FMI 2.0 only */
#endif
    for (int i = 0; i < 7; i++)
        inputs[i] = (fmi2ValueReference)strtoul(argv[5 + i], NULL, 10);
    for (int i = 12; i < argc && n_outputs < 64; i++) {
        if (!strcmp(argv[i], "--cycles") && i + 1 < argc) {
            cycles = atoi(argv[++i]);
            continue;
        }
        if (!strcmp(argv[i], "--inputs") && i + 1 < argc) {
            input_file = argv[++i];
            continue;
        }
#ifdef FMI3
        (void)input_file;
#endif
        if (!strcmp(argv[i], "--integer") && i + 2 < argc && n_ints < 16) {
            int_vrs[n_ints] = (fmi2ValueReference)strtoul(argv[++i], NULL, 10);
            int_values[n_ints++] = atoi(argv[++i]);
            continue;
        }
        outputs[n_outputs++] = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
    }
    if (!strcmp(scenario, "basic"))
        basic();
    else if (!strcmp(scenario, "two"))
        two();
    else if (!strcmp(scenario, "nan"))
        nan_step();
    else if (!strcmp(scenario, "stress"))
        stress(cycles);
#ifndef FMI3
    else if (!strcmp(scenario, "bench") && input_file)
        bench(input_file, int_vrs, int_values, n_ints);
#endif
    else
        fail("unknown scenario");
    printf("done\n");
    return 0;
}
