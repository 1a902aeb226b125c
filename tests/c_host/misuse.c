/* A C host that runs a script of FMI calls, for tests/test_fmi_misuse.py: the FMU's state machine.
 *
 *   misuse FMU_DIR MODEL_IDENTIFIER GUID SCRIPT
 *
 * Compiled as is it is an FMI 2.0 host; with -DFMI3 an FMI 3.0 host (GUID is then the instantiation
 * token). FMU_DIR is the unzipped FMU; its binary is loaded with dlopen(RTLD_NOW | RTLD_LOCAL).
 * SCRIPT holds one call a line: the FMI function's name and its arguments (tests/fmi_state_machine.py):
 *
 *   fmi2Instantiate NAME                    fmi3InstantiateCoSimulation NAME (one instance at a time)
 *   fmi2SetupExperiment T0                  fmi3EnterInitializationMode T0
 *   fmi2DoStep T H                          fmi3DoStep T H
 *   fmi2SetReal VR VALUE [VR VALUE ...]     fmi3SetFloat64, fmi2SetInteger, fmi3SetInt32 alike
 *   fmi2GetReal NVALUES VR ...              fmi3GetFloat64, fmi2GetInteger, fmi3GetInt32 alike
 *   fmi2GetFMUstate SLOT, fmi2SetFMUstate SLOT, fmi2FreeFMUstate SLOT, fmi2SerializedFMUstateSize SLOT
 *   fmi2SerializeFMUstate SLOT FILE         the state's bytes written to FILE
 *   fmi2DeSerializeFMUstate FILE SLOT CUT   FILE's bytes but the last CUT, into SLOT
 *   fmi2SetDebugLogging ON, fmi2GetStatus, fmi2GetRealStatus, ...: the other functions without arguments
 *   @ TEXT                                  a label, printed as "mark TEXT"
 *
 * Lines printed: "call <line index> <function> <status> [values]" after each call (the values of a getter
 * that returned OK or Warning, %.17g), "log <status> <category> <message>" for each message the FMU logs
 * (logging on), and "done" at the end. The host goes on after any status: what the FMU does with a refused
 * call is the test.
 */
#include <dlfcn.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *Instance;
typedef void *State;
typedef unsigned int ValueReference;
typedef int Status; /* 0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal; FMI 3.0 the same numbers */

#define MAX_VALUES 4096
#define SLOTS 8

static char binary[PATH_MAX], resources[PATH_MAX + 16], guid[256];
static void *handle;
static Instance instance;
static State slots[SLOTS];

static void logger(void *env, const char *name, Status status, const char *category, const char *message, ...)
{
    (void)env;
    (void)name;
    char text[16384];
    va_list args;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    for (char *p = text; *p; p++)  /* one line per message */
        if (*p == '\n' || *p == '\r')
            *p = '|';
    printf("log %d %s %s\n", status, category && *category ? category : "-", text);
    fflush(stdout);
}

#ifndef FMI3
#define PLATFORM "linux64"
#define V "fmi2"
typedef struct {
    void (*logger)(void *, const char *, Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, Status);
    void *componentEnvironment;
} Callbacks;
static const Callbacks callbacks = {logger, calloc, free, NULL, NULL};
#else
#define PLATFORM "x86_64-linux"
#define V "fmi3"
static void logger3(void *env, Status status, const char *category, const char *message)
{
    logger(env, NULL, status, category, "%s", message);
}
#endif

static void *symbol(const char *name)
{
    void *f = dlsym(handle, name);
    if (!f) {
        printf("log 4 host the FMU has no function %s\n", name);
        fflush(stdout);
    }
    return f;
}

#define F(type, name) __typeof__(type) name = (__typeof__(type))symbol(function)

/* the arguments of a script line */
static char *words[2 * MAX_VALUES + 8];
static int n_words;

static int split(char *line)
{
    n_words = 0;
    const int most = (int)(sizeof words / sizeof *words);
    for (char *w = strtok(line, " \t\r\n"); w && n_words < most; w = strtok(NULL, " \t\r\n"))
        words[n_words++] = w;
    return n_words;
}

static int slot(int i)
{
    int k = i < n_words ? atoi(words[i]) : 0;
    return k >= 0 && k < SLOTS ? k : 0;
}

static ValueReference vrs[MAX_VALUES];
static double reals[MAX_VALUES];
static int ints[MAX_VALUES];

/* pairs VR VALUE from word 1 on; returns their number */
static size_t pairs(int as_int)
{
    size_t n = 0;
    for (int i = 1; i + 1 < n_words && n < MAX_VALUES; i += 2, n++) {
        vrs[n] = (ValueReference)strtoul(words[i], NULL, 10);
        if (as_int)
            ints[n] = atoi(words[i + 1]);
        else
            reals[n] = strtod(words[i + 1], NULL);
    }
    return n;
}

/* NVALUES VR ... from word 1 on; returns the number of value references */
static size_t refs(size_t *n_values)
{
    size_t n = 0;
    *n_values = n_words > 1 ? strtoul(words[1], NULL, 10) : 0;
    if (*n_values > MAX_VALUES)
        *n_values = MAX_VALUES;
    for (int i = 2; i < n_words && n < MAX_VALUES; i++)
        vrs[n++] = (ValueReference)strtoul(words[i], NULL, 10);
    return n;
}

static double arg(int i)
{
    return i < n_words ? strtod(words[i], NULL) : 0.0;
}

static char *read_file(const char *path, size_t *size)
{
    FILE *fh = fopen(path, "rb");
    if (!fh)
        return NULL;
    fseek(fh, 0, SEEK_END);
    long n = ftell(fh);
    fseek(fh, 0, SEEK_SET);
    char *data = malloc(n > 0 ? (size_t)n : 1);
    *size = fread(data, 1, n > 0 ? (size_t)n : 0, fh);
    fclose(fh);
    return data;
}

/* one call; prints its line. Returns 0, or -1 for an unknown function */
static int call(int index, char *line)
{
    if (split(line) == 0)
        return 0;
    const char *function = words[0];
    if (!strcmp(function, "@")) {
        printf("mark");
        for (int i = 1; i < n_words; i++)
            printf(" %s", words[i]);
        printf("\n");
        return 0;
    }
    Status status = 0;
    double values[MAX_VALUES];
    int ivalues[MAX_VALUES];
    size_t n_out = 0, n_values = 0;
    int out_int = 0;
    const char *short_name = function + 4;
    if (strncmp(function, V, 4) != 0) {
        printf("log 4 host %s is not an " V " function\n", function);
        return -1;
    }
#ifndef FMI3
    if (!strcmp(short_name, "Instantiate")) {
        F(Instance (*)(const char *, int, const char *, const char *, const Callbacks *, int, int), f);
        instance = f ? f(n_words > 1 ? words[1] : "misuse", 1, guid, resources, &callbacks, 0, 1) : NULL;
        status = instance ? 0 : 3;
    } else if (!strcmp(short_name, "SetupExperiment")) {
        F(Status (*)(Instance, int, double, double, int, double), f);
        status = f ? f(instance, 0, 0.0, arg(1), 0, 0.0) : 4;
    } else if (!strcmp(short_name, "EnterInitializationMode") || !strcmp(short_name, "ExitInitializationMode")
               || !strcmp(short_name, "Terminate") || !strcmp(short_name, "Reset")
               || !strcmp(short_name, "CancelStep")) {
        F(Status (*)(Instance), f);
        status = f ? f(instance) : 4;
    } else if (!strcmp(short_name, "DoStep")) {
        F(Status (*)(Instance, double, double, int), f);
        status = f ? f(instance, arg(1), arg(2), 1) : 4;
    } else if (!strcmp(short_name, "SetReal")) {
        F(Status (*)(Instance, const ValueReference *, size_t, const double *), f);
        size_t n = pairs(0);
        status = f ? f(instance, vrs, n, reals) : 4;
    } else if (!strcmp(short_name, "SetInteger")) {
        F(Status (*)(Instance, const ValueReference *, size_t, const int *), f);
        size_t n = pairs(1);
        status = f ? f(instance, vrs, n, ints) : 4;
    } else if (!strcmp(short_name, "GetReal")) {
        F(Status (*)(Instance, const ValueReference *, size_t, double *), f);
        size_t n = refs(&n_values);
        status = f ? f(instance, vrs, n, values) : 4;
        n_out = n;
    } else if (!strcmp(short_name, "GetInteger")) {
        F(Status (*)(Instance, const ValueReference *, size_t, int *), f);
        size_t n = refs(&n_values);
        status = f ? f(instance, vrs, n, ivalues) : 4;
        n_out = n;
        out_int = 1;
    } else if (!strcmp(short_name, "GetStatus") || !strcmp(short_name, "GetBooleanStatus")) {
        F(Status (*)(Instance, int, int *), f);
        status = f ? f(instance, !strcmp(short_name, "GetStatus") ? 0 /* fmi2DoStepStatus */ : 3 /* fmi2Terminated */,
                       ivalues) : 4;
        n_out = 1;
        out_int = 1;
    } else if (!strcmp(short_name, "GetRealStatus")) {
        F(Status (*)(Instance, int, double *), f);
        status = f ? f(instance, 2 /* fmi2LastSuccessfulTime */, values) : 4;
        n_out = 1;
    } else if (!strcmp(short_name, "GetStringStatus")) {
        F(Status (*)(Instance, int, const char **), f);
        const char *text = NULL;
        status = f ? f(instance, 1 /* fmi2PendingStatus */, &text) : 4;
    } else if (!strcmp(short_name, "SetDebugLogging")) {
        F(Status (*)(Instance, int, size_t, const char *const *), f);
        status = f ? f(instance, atoi(n_words > 1 ? words[1] : "1"), 0, NULL) : 4;
    } else if (!strcmp(short_name, "FreeInstance")) {
        F(void (*)(Instance), f);
        if (f)
            f(instance);
        instance = NULL;
    } else if (!strcmp(short_name, "GetFMUstate") || !strcmp(short_name, "FreeFMUstate")) {
        F(Status (*)(Instance, State *), f);
        status = f ? f(instance, &slots[slot(1)]) : 4;
    } else if (!strcmp(short_name, "SetFMUstate")) {
        F(Status (*)(Instance, State), f);
        status = f ? f(instance, slots[slot(1)]) : 4;
    } else if (!strcmp(short_name, "SerializedFMUstateSize")) {
        F(Status (*)(Instance, State, size_t *), f);
        size_t size = 0;
        status = f ? f(instance, slots[slot(1)], &size) : 4;
        values[0] = (double)size;
        n_out = 1;
    } else if (!strcmp(short_name, "SerializeFMUstate")) {
        Status (*size_of)(Instance, State, size_t *) =
            (Status(*)(Instance, State, size_t *))symbol("fmi2SerializedFMUstateSize");
        F(Status (*)(Instance, State, char *, size_t), f);
#else
    if (!strcmp(short_name, "InstantiateCoSimulation")) {
        F(Instance (*)(const char *, const char *, const char *, bool, bool, bool, bool, const ValueReference *, size_t,
                       void *, void (*)(void *, Status, const char *, const char *), void *), f);
        instance = f ? f(n_words > 1 ? words[1] : "misuse", guid, resources, false, true, false, false, NULL, 0, NULL,
                         logger3, NULL) : NULL;
        status = instance ? 0 : 3;
    } else if (!strcmp(short_name, "EnterInitializationMode")) {
        F(Status (*)(Instance, bool, double, double, bool, double), f);
        status = f ? f(instance, false, 0.0, arg(1), false, 0.0) : 4;
    } else if (!strcmp(short_name, "ExitInitializationMode") || !strcmp(short_name, "Terminate")
               || !strcmp(short_name, "Reset") || !strcmp(short_name, "EnterStepMode")
               || !strcmp(short_name, "EnterConfigurationMode") || !strcmp(short_name, "ExitConfigurationMode")
               || !strcmp(short_name, "EnterEventMode")) {
        F(Status (*)(Instance), f);
        status = f ? f(instance) : 4;
    } else if (!strcmp(short_name, "UpdateDiscreteStates")) {
        F(Status (*)(Instance, bool *, bool *, bool *, bool *, bool *, double *), f);
        bool a = false, b = false, c = false, d = false, e = false;
        double next = 0.0;
        status = f ? f(instance, &a, &b, &c, &d, &e, &next) : 4;
    } else if (!strcmp(short_name, "DoStep")) {
        F(Status (*)(Instance, double, double, bool, bool *, bool *, bool *, double *), f);
        bool event = false, terminate = false, early = false;
        double last = NAN;
        status = f ? f(instance, arg(1), arg(2), true, &event, &terminate, &early, &last) : 4;
    } else if (!strcmp(short_name, "SetFloat64")) {
        F(Status (*)(Instance, const ValueReference *, size_t, const double *, size_t), f);
        size_t n = pairs(0);
        status = f ? f(instance, vrs, n, reals, n) : 4;
    } else if (!strcmp(short_name, "SetInt32")) {
        F(Status (*)(Instance, const ValueReference *, size_t, const int *, size_t), f);
        size_t n = pairs(1);
        status = f ? f(instance, vrs, n, ints, n) : 4;
    } else if (!strcmp(short_name, "GetFloat64")) {
        F(Status (*)(Instance, const ValueReference *, size_t, double *, size_t), f);
        size_t n = refs(&n_values);
        status = f ? f(instance, vrs, n, values, n_values) : 4;
        n_out = n_values;
    } else if (!strcmp(short_name, "GetInt32")) {
        F(Status (*)(Instance, const ValueReference *, size_t, int *, size_t), f);
        size_t n = refs(&n_values);
        status = f ? f(instance, vrs, n, ivalues, n_values) : 4;
        n_out = n_values;
        out_int = 1;
    } else if (!strcmp(short_name, "SetDebugLogging")) {
        F(Status (*)(Instance, bool, size_t, const char *const *), f);
        status = f ? f(instance, atoi(n_words > 1 ? words[1] : "1") != 0, 0, NULL) : 4;
    } else if (!strcmp(short_name, "FreeInstance")) {
        F(void (*)(Instance), f);
        if (f)
            f(instance);
        instance = NULL;
    } else if (!strcmp(short_name, "GetFMUState") || !strcmp(short_name, "FreeFMUState")) {
        F(Status (*)(Instance, State *), f);
        status = f ? f(instance, &slots[slot(1)]) : 4;
    } else if (!strcmp(short_name, "SetFMUState")) {
        F(Status (*)(Instance, State), f);
        status = f ? f(instance, slots[slot(1)]) : 4;
    } else if (!strcmp(short_name, "SerializedFMUStateSize")) {
        F(Status (*)(Instance, State, size_t *), f);
        size_t size = 0;
        status = f ? f(instance, slots[slot(1)], &size) : 4;
        values[0] = (double)size;
        n_out = 1;
    } else if (!strcmp(short_name, "SerializeFMUState")) {
        Status (*size_of)(Instance, State, size_t *) =
            (Status(*)(Instance, State, size_t *))symbol("fmi3SerializedFMUStateSize");
        F(Status (*)(Instance, State, char *, size_t), f);
#endif
        /* both versions: the state's size, its bytes, written to the file */
        size_t size = 0;
        status = size_of && f ? size_of(instance, slots[slot(1)], &size) : 4;
        if (status <= 1) {
            char *bytes = malloc(size ? size : 1);
            status = f(instance, slots[slot(1)], bytes, size);
            FILE *fh = n_words > 2 ? fopen(words[2], "wb") : NULL;
            if (fh) {
                fwrite(bytes, 1, size, fh);
                fclose(fh);
            }
            free(bytes);
        }
    } else if (!strcmp(short_name, "DeSerializeFMUstate") || !strcmp(short_name, "DeserializeFMUState")) {
        F(Status (*)(Instance, const char *, size_t, State *), f);
        size_t size = 0;
        char *bytes = n_words > 1 ? read_file(words[1], &size) : NULL;
        size_t cut = n_words > 3 ? strtoul(words[3], NULL, 10) : 0;
        if (!bytes) {
            printf("log 4 host cannot read %s\n", n_words > 1 ? words[1] : "(no file)");
            status = 4;
        } else {
            status = f ? f(instance, bytes, cut < size ? size - cut : 0, &slots[slot(2)]) : 4;
            free(bytes);
        }
    } else {
        printf("log 4 host unknown function %s\n", function);
        fflush(stdout);
        return -1;
    }
    printf("call %d %s %d", index, function, status);
    if (status > 1)  /* a refused getter's values are not values */
        n_out = 0;
    for (size_t i = 0; i < n_out; i++) {
        if (out_int)
            printf(" %d", ivalues[i]);
        else
            printf(" %.17g", values[i]);
    }
    printf("\n");
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: misuse FMU_DIR MODEL_IDENTIFIER GUID SCRIPT\n");
        return 2;
    }
    snprintf(binary, sizeof binary, "%s/binaries/" PLATFORM "/%s.so", argv[1], argv[2]);
#ifndef FMI3
    snprintf(resources, sizeof resources, "file://%s/resources", argv[1]);
#else
    snprintf(resources, sizeof resources, "%s/resources/", argv[1]);  /* FMI 3.0: a path, not a URI */
#endif
    snprintf(guid, sizeof guid, "%s", argv[3]);
    FILE *script = fopen(argv[4], "r");
    if (!script) {
        fprintf(stderr, "cannot open %s\n", argv[4]);
        return 2;
    }
    handle = dlopen(binary, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        printf("log 4 host dlopen: %s\n", dlerror());
        return 1;
    }
    static char line[1 << 17];
    int failed = 0;
    for (int index = 0; fgets(line, sizeof line, script); index++)
        if (call(index, line) != 0)
            failed = 1;
    fclose(script);
    if (instance) {  /* a script that ends with an instance: freed */
        void (*f)(Instance) = (void (*)(Instance))dlsym(handle, V "FreeInstance");
        if (f)
            f(instance);
    }
    if (dlclose(handle) != 0)
        failed = 1;
    printf("done\n");
    return failed ? 3 : 0;
}
