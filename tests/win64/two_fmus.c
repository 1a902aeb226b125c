/* Two different FMI 2.0 FMUs of ours in one Windows C process (tests/test_win64.py): the first starts the
 * Python it carries, the second finds it running and uses it (python_runtime_win.c).
 *
 *   two_fmus.exe DIR_A ID_A GUID_A VR_IN_A VR_OUT_A BASE_A STEP_A  DIR_B ID_B GUID_B VR_IN_B VR_OUT_B BASE_B STEP_B
 *
 * Each FMU: instantiate, initialise, then 4 steps of 10 ms alternating between the two, the input VR set to
 * BASE + STEP k before step k; prints "a <k> <output>" and "b <k> <output>", then "done". */
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, int);
    void *componentEnvironment;
} Callbacks;

typedef struct {
    void *(*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    int (*setup)(void *, int, double, double, int, double);
    int (*enter)(void *);
    int (*exit_)(void *);
    int (*setReal)(void *, const unsigned *, size_t, const double *);
    int (*getReal)(void *, const unsigned *, size_t, double *);
    int (*doStep)(void *, double, double, int);
    int (*terminate)(void *);
    void (*freeInstance)(void *);
    void *c;
    unsigned in, out;
    double base, step;
} Fmu;

static void logger(void *env, const char *name, int status, const char *category, const char *message, ...)
{
    (void)env, (void)name;
    printf("log %d %s %s\n", status, category ? category : "-", message);
    fflush(stdout);
}

static const Callbacks callbacks = {logger, calloc, free, NULL, NULL};

static void fail(const char *what)
{
    printf("error %s\n", what);
    fflush(stdout);
    exit(1);
}

static void open_fmu(Fmu *f, char **argv)
{
    char path[4096], resources[4096];
    snprintf(path, sizeof path, "%s\\binaries\\win64\\%s.dll", argv[0], argv[1]);
    HMODULE h = LoadLibraryExA(path, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
    if (!h)
        fail(path);
#define GET(field, name) if (!(*(FARPROC *)&f->field = GetProcAddress(h, name))) fail(name)
    GET(instantiate, "fmi2Instantiate");
    GET(setup, "fmi2SetupExperiment");
    GET(enter, "fmi2EnterInitializationMode");
    GET(exit_, "fmi2ExitInitializationMode");
    GET(setReal, "fmi2SetReal");
    GET(getReal, "fmi2GetReal");
    GET(doStep, "fmi2DoStep");
    GET(terminate, "fmi2Terminate");
    GET(freeInstance, "fmi2FreeInstance");
    snprintf(resources, sizeof resources, "file:///%s/resources", argv[0]);
    for (char *p = resources; *p; p++)
        if (*p == '\\')
            *p = '/';
    f->in = (unsigned)strtoul(argv[3], NULL, 10);
    f->out = (unsigned)strtoul(argv[4], NULL, 10);
    f->base = atof(argv[5]);
    f->step = atof(argv[6]);
    f->c = f->instantiate(argv[1], 1, argv[2], resources, &callbacks, 0, 0);
    if (!f->c)
        fail("fmi2Instantiate");
    if (f->setup(f->c, 0, 0.0, 0.0, 0, 0.0) || f->enter(f->c) || f->exit_(f->c))
        fail("initialisation");
}

int main(int argc, char **argv)
{
    if (argc != 15) {
        fprintf(stderr, "usage: two_fmus (DIR ID GUID VR_IN VR_OUT BASE STEP) x 2\n");
        return 2;
    }
    Fmu a, b;
    open_fmu(&a, argv + 1);
    open_fmu(&b, argv + 8);
    for (int k = 0; k < 4; k++) {
        double ua = a.base + a.step * k, ub = b.base + b.step * k, y;
        if (a.setReal(a.c, &a.in, 1, &ua) || a.doStep(a.c, k * 0.01, 0.01, 1) || a.getReal(a.c, &a.out, 1, &y))
            fail("step a");
        printf("a %d %.17g\n", k, y);
        if (b.setReal(b.c, &b.in, 1, &ub) || b.doStep(b.c, k * 0.01, 0.01, 1) || b.getReal(b.c, &b.out, 1, &y))
            fail("step b");
        printf("b %d %.17g\n", k, y);
        fflush(stdout);
    }
    a.terminate(a.c);
    a.freeInstance(a.c);
    b.terminate(b.c);
    b.freeInstance(b.c);
    printf("done\n");
    return 0;
}
