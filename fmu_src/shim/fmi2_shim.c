/* The FMI 2.0 binary of the slewing bearing FMU on Linux: a thin layer in front of pythonfmu's.
 *
 * build_fmu.py compiles this file as binaries/linux64/<modelIdentifier>.so and moves
 * pythonfmu's binary beside it as pythonfmu-export.so; fmu_build/win64.py compiles it with mingw-w64 as
 * binaries/win64/<modelIdentifier>.dll, with python_runtime_win.c, beside pythonfmu-export.dll. Every fmi2 function is forwarded to
 * pythonfmu's; this layer adds three things:
 *
 * 1. Python. Before pythonfmu's binary is loaded, python_runtime_load() makes the Python
 *    named in resources/python_runtime.txt (or by SLEWING_FMU_PYTHONHOME) visible to it, with
 *    its home set; when that Python is missing, fmi2Instantiate says so through the host's
 *    logger and returns NULL. The host needs no LD_PRELOAD and no Python on its PATH.
 *
 * 2. Status. A message logged as Warning leaves the call's status OK (fmusim ends a run on
 *    fmi2Warning). pythonfmu maps a refused step (do_step returning False) to fmi2Discard and then
 *    reports fmi2Terminated = true for the rest of the run, so every master stops. Here the
 *    status of each call is the worst status the slave logged during it (the slave logs a
 *    refused step as Discard, an instance that cannot continue as Error), and fmi2Terminated
 *    is true only in the error state: after a Discard the state is the one before the step,
 *    fmi2LastSuccessfulTime is the start of the refused step, and the master may retry
 *    (fmi2SetFMUstate) or go on with other inputs.
 *
 * 3. Logging. pythonfmu drops every message, errors included, when logging is off. Here
 *    pythonfmu always logs to this layer, which passes Error and Fatal messages to the host
 *    always and the others when the host asked for them (fmi2Instantiate's loggingOn,
 *    fmi2SetDebugLogging and its categories), as FMI 2.0 section 2.1.5 describes.
 *
 * Our own declarations of the FMI 2.0 types (the standard's ABI, fmi2TypesPlatform "default").
 */
#include "shim_platform.h"  /* first: glibc_compat.h on Linux, windows.h on Windows */
#include "python_runtime.h"

#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT SHIM_EXPORT
#define INNER_BINARY SHIM_INNER_BINARY

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

/* ---- pythonfmu's functions -------------------------------------------------------------- */
#define FMI2_FUNCTIONS(X)                                                                                  \
    X(const char *, fmi2GetTypesPlatform, (void))                                                          \
    X(const char *, fmi2GetVersion, (void))                                                                \
    X(fmi2Status, fmi2SetDebugLogging, (fmi2Component, fmi2Boolean, size_t, const fmi2String[]))          \
    X(fmi2Component, fmi2Instantiate,                                                                      \
      (fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean)) \
    X(void, fmi2FreeInstance, (fmi2Component))                                                             \
    X(fmi2Status, fmi2SetupExperiment, (fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real)) \
    X(fmi2Status, fmi2EnterInitializationMode, (fmi2Component))                                            \
    X(fmi2Status, fmi2ExitInitializationMode, (fmi2Component))                                             \
    X(fmi2Status, fmi2Terminate, (fmi2Component))                                                          \
    X(fmi2Status, fmi2Reset, (fmi2Component))                                                              \
    X(fmi2Status, fmi2GetReal, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]))           \
    X(fmi2Status, fmi2GetInteger, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]))     \
    X(fmi2Status, fmi2GetBoolean, (fmi2Component, const fmi2ValueReference[], size_t, fmi2Boolean[]))     \
    X(fmi2Status, fmi2GetString, (fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]))       \
    X(fmi2Status, fmi2SetReal, (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]))     \
    X(fmi2Status, fmi2SetInteger, (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[])) \
    X(fmi2Status, fmi2SetBoolean, (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Boolean[])) \
    X(fmi2Status, fmi2SetString, (fmi2Component, const fmi2ValueReference[], size_t, const fmi2String[])) \
    X(fmi2Status, fmi2GetFMUstate, (fmi2Component, fmi2FMUstate *))                                        \
    X(fmi2Status, fmi2SetFMUstate, (fmi2Component, fmi2FMUstate))                                          \
    X(fmi2Status, fmi2FreeFMUstate, (fmi2Component, fmi2FMUstate *))                                       \
    X(fmi2Status, fmi2SerializedFMUstateSize, (fmi2Component, fmi2FMUstate, size_t *))                     \
    X(fmi2Status, fmi2SerializeFMUstate, (fmi2Component, fmi2FMUstate, fmi2Byte[], size_t))              \
    X(fmi2Status, fmi2DeSerializeFMUstate, (fmi2Component, const fmi2Byte[], size_t, fmi2FMUstate *))      \
    X(fmi2Status, fmi2GetDirectionalDerivative,                                                            \
      (fmi2Component, const fmi2ValueReference[], size_t, const fmi2ValueReference[], size_t, const fmi2Real[], fmi2Real[])) \
    X(fmi2Status, fmi2SetRealInputDerivatives,                                                             \
      (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[], const fmi2Real[]))          \
    X(fmi2Status, fmi2GetRealOutputDerivatives,                                                            \
      (fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[], fmi2Real[]))                \
    X(fmi2Status, fmi2DoStep, (fmi2Component, fmi2Real, fmi2Real, fmi2Boolean))                           \
    X(fmi2Status, fmi2CancelStep, (fmi2Component))                                                         \
    X(fmi2Status, fmi2GetStatus, (fmi2Component, const fmi2StatusKind, fmi2Status *))                     \
    X(fmi2Status, fmi2GetRealStatus, (fmi2Component, const fmi2StatusKind, fmi2Real *))                   \
    X(fmi2Status, fmi2GetIntegerStatus, (fmi2Component, const fmi2StatusKind, fmi2Integer *))             \
    X(fmi2Status, fmi2GetBooleanStatus, (fmi2Component, const fmi2StatusKind, fmi2Boolean *))             \
    X(fmi2Status, fmi2GetStringStatus, (fmi2Component, const fmi2StatusKind, fmi2String *))

#define MEMBER(ret, name, args) ret(*name) args;
static struct {
    FMI2_FUNCTIONS(MEMBER)
} inner;
static int inner_loaded = 0;
static pthread_mutex_t inner_lock = PTHREAD_MUTEX_INITIALIZER;

#define RESOLVE(ret, name, args)                                                               \
    if (status == 0 && !(*(void **)&inner.name = dlsym(handle, #name))) {                      \
        snprintf(err, size, "%s has no function %s", INNER_BINARY, #name);                     \
        status = -1;                                                                           \
    }
/* Load Python, then pythonfmu's binary and its functions, once. 0, or -1 with a message. */
static int load_inner(char *err, size_t size)
{
    pthread_mutex_lock(&inner_lock);
    int status = 0;
    if (inner_loaded && !python_runtime_binary_open()) {
        snprintf(err, size, "the FMU's binary was released (the process is exiting)");
        status = -1;
    } else if (!inner_loaded) {
        void *handle = python_runtime_start((const void *)&load_inner, INNER_BINARY, err, size);
        status = handle ? 0 : -1;
        if (handle) {
            FMI2_FUNCTIONS(RESOLVE)
        }
        inner_loaded = (status == 0);
    }
    pthread_mutex_unlock(&inner_lock);
    return status;
}

/* ---- one instance ----------------------------------------------------------------------- */
typedef struct {
    fmi2Component inner;               /* pythonfmu's component */
    fmi2CallbackFunctions host;        /* the host's callbacks */
    fmi2CallbackFunctions mine;        /* given to pythonfmu: our logger, this instance as environment */
    char *name;
    int logging_on;
    size_t n_categories;
    char **categories;
    fmi2Status logged;                 /* worst status the slave logged during the current call */
    int error;                         /* an Error or Fatal was returned: fmi2Terminated is true */
} Instance;

static void free_categories(Instance *in)
{
    for (size_t i = 0; i < in->n_categories; i++)
        free(in->categories[i]);
    free(in->categories);
    in->categories = NULL;
    in->n_categories = 0;
}

static int category_logged(const Instance *in, fmi2String category)
{
    if (!in->logging_on)
        return 0;
    if (in->n_categories == 0)
        return 1;
    for (size_t i = 0; i < in->n_categories; i++)
        if (category && !strcmp(category, in->categories[i]))
            return 1;
    return 0;
}

/* Pass a message to the host's logger: the message is plain text (pythonfmu formats nothing),
 * and the host's logger takes a format string, so '%' is doubled. */
static void host_log(const Instance *in, fmi2Status status, fmi2String category, const char *text)
{
    if (!in->host.logger)
        return;
    size_t n = strlen(text), extra = 0;
    for (size_t i = 0; i < n; i++)
        extra += text[i] == '%';
    char *escaped = malloc(n + extra + 1);
    if (!escaped)
        return;
    char *q = escaped;
    for (size_t i = 0; i < n; i++) {
        *q++ = text[i];
        if (text[i] == '%')
            *q++ = '%';
    }
    *q = '\0';
    in->host.logger(in->host.componentEnvironment, in->name, status, category, escaped);
    free(escaped);
}

static void shim_logger(fmi2ComponentEnvironment environment, fmi2String instance_name, fmi2Status status,
                        fmi2String category, fmi2String message, ...)
{
    (void)instance_name;
    Instance *in = (Instance *)environment;
    if (!in || !message)
        return;
    if (status > in->logged && status != fmi2Pending)
        in->logged = status;
    if (status >= fmi2Error || category_logged(in, category))
        host_log(in, status, category, message);
}

static fmi2Status begin(Instance *in)
{
    in->logged = fmi2OK;
    return fmi2OK;
}

/* The status of a call: pythonfmu's, raised to what the slave logged (a logged Discard only
 * where FMI 2.0 allows Discard: fmi2DoStep). */
static fmi2Status finish(Instance *in, fmi2Status status, int discard_allowed)
{
    fmi2Status logged = in->logged;
    if (logged == fmi2Discard && !discard_allowed)
        logged = fmi2Warning;
    else if (logged == fmi2Warning)
        logged = fmi2OK;  /* a warning (safety factor, edge loading) is for the log: the call went well, and
                           * hosts such as fmusim end the run on a call's fmi2Warning */
    if (logged > status && status != fmi2Pending)
        status = logged;
    if (status == fmi2Error || status == fmi2Fatal)
        in->error = 1;
    in->logged = fmi2OK;
    return status;
}

#undef IN  /* windows.h defines IN as nothing */
#define IN ((Instance *)c)
/* pythonfmu's binary is released at exit (python_runtime.c): a host that frees instances later
 * (from a static destructor) gets fmi2Error instead of a call into a torn-down binary */
#define FORWARD(call) (!python_runtime_binary_open() ? fmi2Error : (begin(IN), finish(IN, inner.call, 0)))

/* ---- FMI 2.0 functions ------------------------------------------------------------------ */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    if (!functions || !instanceName)
        return NULL;
    char err[2048] = "";
#ifdef _WIN32
    if (python_runtime_check_location(fmuResourceLocation, err, sizeof err) != 0) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError", "%s", err);
        return NULL;
    }
#endif
    if (load_inner(err, sizeof err) != 0) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError", "%s", err);
        return NULL;
    }
    Instance *in = calloc(1, sizeof *in);
    if (!in || !(in->name = strdup(instanceName))) {
        free(in);
        return NULL;
    }
    in->host = *functions;
    in->mine = *functions;
    in->mine.logger = shim_logger;
    in->mine.componentEnvironment = in;
    in->logging_on = loggingOn;
    begin(in);
    /* pythonfmu always logs to us; we filter */
    in->inner = inner.fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation, &in->mine, visible, 1);
    if (!in->inner) {
        free(in->name);
        free(in);
        return NULL;
    }
    in->logged = fmi2OK;
    return in;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    if (!c)
        return;
    if (python_runtime_binary_open())
        inner.fmi2FreeInstance(IN->inner);
    free_categories(IN);
    free(IN->name);
    free(IN);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[])
{
    free_categories(IN);
    IN->logging_on = loggingOn;
    if (nCategories > 0 && categories) {
        IN->categories = calloc(nCategories, sizeof(char *));
        if (!IN->categories)
            return fmi2Error;
        for (size_t i = 0; i < nCategories; i++)
            IN->categories[i] = strdup(categories[i] ? categories[i] : "");
        IN->n_categories = nCategories;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    return FORWARD(fmi2SetupExperiment(IN->inner, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime));
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return FORWARD(fmi2EnterInitializationMode(IN->inner)); }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return FORWARD(fmi2ExitInitializationMode(IN->inner)); }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return FORWARD(fmi2Terminate(IN->inner)); }

EXPORT fmi2Status fmi2Reset(fmi2Component c)
{
    fmi2Status status = FORWARD(fmi2Reset(IN->inner));
    if (status <= fmi2Warning)
        IN->error = 0;
    return status;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    return FORWARD(fmi2GetReal(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    return FORWARD(fmi2GetInteger(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    return FORWARD(fmi2GetBoolean(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    return FORWARD(fmi2GetString(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    return FORWARD(fmi2SetReal(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    return FORWARD(fmi2SetInteger(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    return FORWARD(fmi2SetBoolean(IN->inner, vr, nvr, value));
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    return FORWARD(fmi2SetString(IN->inner, vr, nvr, value));
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    if (state && *state && python_runtime_binary_open()) {  /* FMI 2.0: a non-NULL state is updated */
        fmi2FMUstate old = *state;
        inner.fmi2FreeFMUstate(IN->inner, &old);
        *state = NULL;
    }
    return FORWARD(fmi2GetFMUstate(IN->inner, state));
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    fmi2Status status = FORWARD(fmi2SetFMUstate(IN->inner, state));
    if (status <= fmi2Warning)
        IN->error = 0;
    return status;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    if (!state || !*state)
        return fmi2OK;
    fmi2Status status = FORWARD(fmi2FreeFMUstate(IN->inner, state));
    *state = NULL;
    return status;
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    return FORWARD(fmi2SerializedFMUstateSize(IN->inner, state, size));
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    return FORWARD(fmi2SerializeFMUstate(IN->inner, state, bytes, size));
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    return FORWARD(fmi2DeSerializeFMUstate(IN->inner, bytes, size, state));
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const fmi2Real dz[],
                                               fmi2Real du[])
{
    return FORWARD(fmi2GetDirectionalDerivative(IN->inner, u, nu, z, nz, dz, du));
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[])
{
    return FORWARD(fmi2SetRealInputDerivatives(IN->inner, vr, nvr, order, value));
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[])
{
    return FORWARD(fmi2GetRealOutputDerivatives(IN->inner, vr, nvr, order, value));
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                             fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    if (!python_runtime_binary_open())
        return fmi2Error;
    begin(IN);
    fmi2Status status = inner.fmi2DoStep(IN->inner, currentCommunicationPoint, communicationStepSize,
                                         noSetFMUStatePriorToCurrentPoint);
    return finish(IN, status, 1);
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return FORWARD(fmi2CancelStep(IN->inner)); }

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    if (s == fmi2DoStepStatus && value) {  /* steps are synchronous: never pending */
        *value = IN->error ? fmi2Error : fmi2OK;
        return fmi2OK;
    }
    return fmi2Discard;  /* FMI 2.0: Discard when the status is not available */
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    return FORWARD(fmi2GetRealStatus(IN->inner, s, value));
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    if (s == fmi2Terminated && value) {
        *value = IN->error ? 1 : 0;
        return fmi2OK;
    }
    return fmi2Discard;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
