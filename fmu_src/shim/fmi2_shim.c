/* The FMI 2.0 binary of the slewing bearing FMU on Linux: a thin layer in front of pythonfmu's.
 *
 * build_fmu.py compiles this file as binaries/linux64/<modelIdentifier>.so and moves
 * pythonfmu's binary beside it as pythonfmu-export.so; fmu_build/win64.py compiles it with mingw-w64 as
 * binaries/win64/<modelIdentifier>.dll, with python_runtime_win.c, beside pythonfmu-export.dll. Every fmi2 function the
 * standard allows is forwarded to pythonfmu's; this layer adds four things:
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
 *    fmi2LastSuccessfulTime is the start of the refused step, and the master may retry that
 *    step from its start, with other inputs, or restore a state (fmi2SetFMUstate).
 *
 * 3. Logging. pythonfmu drops every message, errors included, when logging is off. Here
 *    pythonfmu always logs to this layer, which passes Error and Fatal messages to the host
 *    always and the others when the host asked for them (fmi2Instantiate's loggingOn,
 *    fmi2SetDebugLogging and its categories), as FMI 2.0 section 2.1.5 describes.
 *
 * 4. The standard. Each instance's state (Instantiated, InitializationMode, StepComplete, StepFailed,
 *    Terminated, Error) is tracked and every call checked against FMI 2.0's co-simulation table
 *    (section 4.2.4), every value reference against resources/fmi_variables.tsv (the FMU's variables:
 *    type, causality, variability; shim_rules.h), and fmi2DoStep's arguments (a step size > 0, a
 *    currentCommunicationPoint at the instance's time: the start time, the end of the last
 *    successful step, the start of a refused step, or the time of the state set last). A call the
 *    standard forbids returns fmi2Error with one Error line in the log, is not forwarded and changes
 *    nothing. FMU states are pythonfmu's wrapped with their communication time; a serialized state
 *    starts with a header (shim_rules.h: magic, format version, the payload's CRC-32, the GUID's hash,
 *    the time, the length) that fmi2DeSerializeFMUstate checks before pythonfmu reads the payload.
 *    pythonfmu returns fmi2Fatal for any Python exception it catches (and clears): here that is the
 *    call's fmi2Error, logged with the exception. StepFailed (after a Discard) allows what StepComplete
 *    allows (see 2.). The state Error (after an Error of the model) allows what the standard's table
 *    allows there: the getters, fmi2GetStatus and the like, the FMU state functions, fmi2Reset,
 *    fmi2FreeInstance and fmi2SetDebugLogging; fmi2SetFMUstate leaves it for the state the Error
 *    came in (StepComplete for a step).
 *
 * Our own declarations of the FMI 2.0 types (the standard's ABI, fmi2TypesPlatform "default").
 */
#include "shim_platform.h"  /* first: glibc_compat.h on Linux, windows.h on Windows */
#include "python_runtime.h"
#include "shim_rules.h"

#include <limits.h>
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
/* The states of FMI 2.0 co-simulation (section 4.2.4) this layer tracks. StepInProgress never
 * exists (steps are synchronous). StepFailed is the state after a Discard'ed step: the state is
 * the one before the step, and unlike the standard's stepFailed it allows what StepComplete allows
 * (the master may set other inputs and retry the step from its start, or restore a state). Error: the
 * model returned fmi2Error (or fmi2Fatal); fmi2Terminated is then true until fmi2SetFMUstate or
 * fmi2Reset, and only what the standard's table allows in the state error is accepted (the getters,
 * the status functions, the FMU state functions, fmi2Reset, fmi2FreeInstance). */
enum {
    Instantiated = 1 << 0,
    InitializationMode = 1 << 1,
    StepComplete = 1 << 2,
    StepFailed = 1 << 3,
    Terminated = 1 << 4,
    ErrorState = 1 << 5,
};
static const char *state_name(int s)
{
    switch (s) {
    case Instantiated: return "Instantiated";
    case InitializationMode: return "InitializationMode";
    case StepComplete: return "StepComplete";
    case StepFailed: return "StepFailed";
    case Terminated: return "Terminated";
    default: return "Error";
    }
}

/* Which states allow each function (the standard's table; StepFailed as StepComplete, see above) */
#define ALL_STATES (Instantiated | InitializationMode | StepComplete | StepFailed | Terminated | ErrorState)
#define STEPPING (StepComplete | StepFailed)
#define MASK_SetupExperiment Instantiated
#define MASK_EnterInitializationMode Instantiated
#define MASK_ExitInitializationMode InitializationMode
#define MASK_Terminate STEPPING
#define MASK_Reset ALL_STATES
#define MASK_Get (InitializationMode | STEPPING | Terminated | ErrorState)
#define MASK_Set (Instantiated | InitializationMode | STEPPING)
#define MASK_GetFMUstate ALL_STATES
#define MASK_StateData ALL_STATES /* Set, Free, (De)Serialize: from Error too (FMI 2.0 section 2.1.3) */
#define MASK_GetDirectionalDerivative (InitializationMode | STEPPING | Terminated | ErrorState)
#define MASK_SetRealInputDerivatives (Instantiated | InitializationMode | STEPPING)
#define MASK_GetRealOutputDerivatives (STEPPING | Terminated | ErrorState)
#define MASK_DoStep STEPPING
#define MASK_CancelStep 0
#define MASK_Status (STEPPING | Terminated | ErrorState)

/* where the expected currentCommunicationPoint comes from (for the message) */
enum { TIME_START, TIME_STEP, TIME_DISCARD, TIME_STATE };

/* what pythonfmu logs (with fmi2Fatal, returning fmi2Fatal) for an exception raised in Python */
#define PYTHON_EXCEPTION "Fatal py exception encountered: "

typedef struct {
    fmi2Component inner;               /* pythonfmu's component */
    fmi2CallbackFunctions host;        /* the host's callbacks */
    fmi2CallbackFunctions mine;        /* given to pythonfmu: our logger, this instance as environment */
    char *name;
    char *guid;                        /* the token in a serialized state's header */
    ShimLog log;                       /* to the host's logger: loggingOn, fmi2SetDebugLogging's categories */
    const char *function;              /* the fmi2 function being called */
    fmi2Status logged;                 /* worst status the slave logged during the current call */
    int python_exception;              /* pythonfmu reported a Python exception during the current call */
    int state;                         /* Instantiated, ... */
    int before_error;                  /* in the state Error: the state the Error came in (fmi2SetFMUstate's) */
    double start_time;                 /* fmi2SetupExperiment's startTime */
    double time;                       /* the currentCommunicationPoint the next fmi2DoStep must give */
    int time_origin;                   /* TIME_START, ... */
    ShimVariables variables;           /* resources/fmi_variables.tsv */
    ShimState *states;                 /* the FMU states handed to the host */
} Instance;

/* The instance's log sink (shim_rules.h): the message is plain text (pythonfmu formats nothing),
 * and the host's logger takes a format string, so '%' is doubled. */
static void log_sink(void *layer, int status, const char *category, const char *text)
{
    const Instance *in = (const Instance *)layer;
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
    in->host.logger(in->host.componentEnvironment, in->name, (fmi2Status)status, category, escaped);
    free(escaped);
}

static void shim_logger(fmi2ComponentEnvironment environment, fmi2String instance_name, fmi2Status status,
                        fmi2String category, fmi2String message, ...)
{
    (void)instance_name;
    Instance *in = (Instance *)environment;
    if (!in || !message)
        return;
    if (status == fmi2Fatal && !strncmp(message, PYTHON_EXCEPTION, strlen(PYTHON_EXCEPTION))) {
        /* a Python exception, caught and cleared by pythonfmu: the instance's call failed, the
         * process and its memory are sound: an Error of this instance, not a Fatal of all */
        in->python_exception = 1;
        size_t n = strlen(message) + 128;
        char *text = malloc(n);
        if (text) {
            shim_format(text, n, "%s: Python exception in the model: %s", in->function ? in->function : "fmi2",
                        message + strlen(PYTHON_EXCEPTION));
            if (status > in->logged)
                in->logged = fmi2Error;
            shim_log_text(&in->log, fmi2Error, "logStatusError", text);
            free(text);
            return;
        }
        status = fmi2Error;
    }
    if (status > in->logged && status != fmi2Pending)
        in->logged = status;
    shim_log_text(&in->log, status, category, message);
}

/* A call refused by this layer: logged as an Error, not forwarded, nothing changed: fmi2Error. */
#define refuse(in, ...) ((fmi2Status)shim_refuse(&(in)->log, __VA_ARGS__))

static void state_list(int mask, char *buf, size_t size)
{
    buf[0] = '\0';
    if (!mask) {
        shim_format(buf, size, "StepInProgress, which this FMU never enters: its steps are synchronous");
        return;
    }
    for (int s = 1; s <= ErrorState; s <<= 1)
        if (mask & s) {
            size_t n = strlen(buf);
            shim_format(buf + n, size - n, "%s%s", n ? ", " : "", state_name(s));
        }
}

/* 0 where the instance's state allows the call, else fmi2Error logged */
static int not_allowed(Instance *in, const char *function, int mask)
{
    if (in->state & mask)
        return 0;
    char allowed[256];
    state_list(mask, allowed, sizeof allowed);
    refuse(in, "%s: not allowed in state %s (allowed: %s)", function, state_name(in->state), allowed);
    return 1;
}

static void begin(Instance *in, const char *function)
{
    in->function = function;
    in->logged = fmi2OK;
    in->python_exception = 0;
}

/* The status of a call: pythonfmu's, raised to what the slave logged (a logged Discard only
 * where FMI 2.0 allows Discard: fmi2DoStep). A Python exception (pythonfmu's fmi2Fatal) is the
 * call's fmi2Error. With enters_error, an Error moves the instance to the state Error. */
static fmi2Status finish(Instance *in, fmi2Status status, int discard_allowed, int enters_error)
{
    fmi2Status logged = in->logged;
    if (status == fmi2Fatal && in->python_exception)
        status = fmi2Error;
    if (logged == fmi2Discard && !discard_allowed)
        logged = fmi2Warning;
    else if (logged == fmi2Warning)
        logged = fmi2OK;  /* a warning (safety factor, edge loading) is for the log: the call went well, and
                           * hosts such as fmusim end the run on a call's fmi2Warning */
    if (logged > status && status != fmi2Pending)
        status = logged;
    if ((status == fmi2Error || status == fmi2Fatal) && enters_error && in->state != ErrorState) {
        in->before_error = in->state;
        in->state = ErrorState;
    }
    in->logged = fmi2OK;
    in->python_exception = 0;
    in->function = NULL;
    return status;
}

#undef IN  /* windows.h defines IN as nothing */
#define IN ((Instance *)c)
/* pythonfmu's binary is released at exit (python_runtime.c): a host that frees instances later
 * (from a static destructor) gets fmi2Error instead of a call into a torn-down binary */
#define CHECK(function, mask)                                      \
    do {                                                           \
        if (!c || !python_runtime_binary_open())                   \
            return fmi2Error;                                      \
        if (not_allowed(IN, function, mask))                       \
            return fmi2Error;                                      \
    } while (0)
#define FORWARD(function, call) (begin(IN, function), finish(IN, inner.call, 0, 1))

/* The end of a life-cycle call: where it succeeded (status OK or Warning) the instance is in state next
 * (0: the state it is in) and, where start is given, the experiment starts at *start: the
 * currentCommunicationPoint the first fmi2DoStep must give. Returns status. */
static fmi2Status moved(Instance *in, fmi2Status status, int next, const double *start)
{
    if (status <= fmi2Warning) {
        if (next)
            in->state = next;
        if (start) {
            in->start_time = in->time = *start;
            in->time_origin = TIME_START;
        }
    }
    return status;
}

/* Value references of the type (NULL-safe): 0, or fmi2Error logged naming the first unknown one */
static int check_references(Instance *in, const char *function, const char *type, const fmi2ValueReference vr[],
                            size_t nvr, const void *value, int set)
{
    if (nvr == 0)
        return 0;
    if (!vr || !value) {
        refuse(in, "%s: %s is NULL with nvr = %lu", function, !vr ? "vr" : "value", (unsigned long)nvr);
        return 1;
    }
    int phase = in->state == Instantiated ? SHIM_BEFORE_INITIALIZATION
                : in->state == InitializationMode ? SHIM_INITIALIZING : SHIM_RUNNING;
    for (size_t i = 0; i < nvr; i++) {
        const ShimVariable *v = shim_variable_find(&in->variables, type, vr[i]);
        if (!v && !strcmp(type, "Integer"))  /* FMI 2.0: enumerations are got and set as Integer */
            v = shim_variable_find(&in->variables, "Enumeration", vr[i]);
        if (!v) {
            refuse(in, "%s: value reference %u is not a%s %s variable of this FMU", function, vr[i],
                   strchr("AEIOU", type[0]) ? "n" : "", type);
            return 1;
        }
        char why[256];
        if (set && !shim_may_set(v, phase, "fmi2ExitInitializationMode", why, sizeof why)) {
            refuse(in, "%s: %s (value reference %u) %s", function, v->name, vr[i], why);
            return 1;
        }
    }
    return 0;
}

/* ---- FMI 2.0 functions ------------------------------------------------------------------ */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

static void instantiate_error(const fmi2CallbackFunctions *functions, fmi2String instanceName, const char *err)
{
    if (functions->logger)
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError", "%s", err);
}

static void free_instance(Instance *in)
{
    shim_log_free(&in->log);
    shim_variables_free(&in->variables);
    while (in->states) {
        ShimState *s = in->states;
        in->states = s->next;
        free(s);
    }
    free(in->name);
    free(in->guid);
    free(in);
}

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    if (!functions || !instanceName)
        return NULL;
    char err[2048] = "";
#ifdef _WIN32
    if (python_runtime_check_location(fmuResourceLocation, err, sizeof err) != 0) {
        instantiate_error(functions, instanceName, err);
        return NULL;
    }
#endif
    Instance *in = calloc(1, sizeof *in);
    if (!in || !(in->name = strdup(instanceName)) || !(in->guid = strdup(fmuGUID ? fmuGUID : ""))) {
        if (in)
            free_instance(in);
        instantiate_error(functions, instanceName, "fmi2Instantiate: out of memory");
        return NULL;
    }
    if (shim_variables_load(&in->variables, fmuResourceLocation, err, sizeof err) != 0) {
        char text[2200];
        shim_format(text, sizeof text, "fmi2Instantiate: %s", err);
        instantiate_error(functions, instanceName, text);
        free_instance(in);
        return NULL;
    }
    if (load_inner(err, sizeof err) != 0) {
        instantiate_error(functions, instanceName, err);
        free_instance(in);
        return NULL;
    }
    in->host = *functions;
    in->mine = *functions;
    in->mine.logger = shim_logger;
    in->mine.componentEnvironment = in;
    in->log.sink = in->host.logger ? log_sink : NULL;
    in->log.layer = in;
    in->log.on = loggingOn;
    begin(in, "fmi2Instantiate");
    /* pythonfmu always logs to us; we filter */
    in->inner = inner.fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation, &in->mine, visible, 1);
    if (!in->inner) {
        free_instance(in);
        return NULL;
    }
    in->logged = fmi2OK;
    in->function = NULL;
    in->state = Instantiated;
    return in;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    if (!c)
        return;
    if (python_runtime_binary_open()) {
        for (ShimState *s = IN->states; s; s = s->next) {
            fmi2FMUstate inner_state = s->inner;
            if (inner_state)
                inner.fmi2FreeFMUstate(IN->inner, &inner_state);
        }
        inner.fmi2FreeInstance(IN->inner);
    }
    free_instance(IN);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[])
{
    if (!c)
        return fmi2Error;
    if (nCategories > 0 && !categories)
        return refuse(IN, "fmi2SetDebugLogging: categories is NULL with nCategories = %lu", (unsigned long)nCategories);
    if (shim_log_set(&IN->log, loggingOn, nCategories, categories) != 0)
        return refuse(IN, "fmi2SetDebugLogging: out of memory");
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    CHECK("fmi2SetupExperiment", MASK_SetupExperiment);
    char a[32], b[32];
    if (!(startTime == startTime) || startTime - startTime != 0)
        return refuse(IN, "fmi2SetupExperiment: startTime = %s must be finite", shim_double(a, startTime));
    if (stopTimeDefined && !(stopTime >= startTime))
        return refuse(IN, "fmi2SetupExperiment: stopTime = %s is before startTime = %s", shim_double(a, stopTime),
                      shim_double(b, startTime));
    return moved(IN, FORWARD("fmi2SetupExperiment", fmi2SetupExperiment(IN->inner, toleranceDefined, tolerance,
                                                                         startTime, stopTimeDefined, stopTime)),
                 0, &startTime);
}

/* The life-cycle calls without arguments: checked, forwarded, and where pythonfmu's call succeeds the
 * instance moves to `next`, with the experiment starting at *start where start is given */
#define LIFE_CYCLE(Name, next, start)                                                  \
    EXPORT fmi2Status fmi2##Name(fmi2Component c)                                      \
    {                                                                                  \
        CHECK("fmi2" #Name, MASK_##Name);                                              \
        return moved(IN, FORWARD("fmi2" #Name, fmi2##Name(IN->inner)), next, start);  \
    }
static const double DEFAULT_START_TIME = 0.0;  /* fmi2Reset's: as before fmi2SetupExperiment */
LIFE_CYCLE(EnterInitializationMode, InitializationMode, NULL)
LIFE_CYCLE(ExitInitializationMode, StepComplete, &IN->start_time)
LIFE_CYCLE(Terminate, Terminated, NULL)
LIFE_CYCLE(Reset, Instantiated, &DEFAULT_START_TIME)

#define GET_SET(Kind, type_name, value_type, set)                                                                  \
    EXPORT fmi2Status fmi2##Kind(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, value_type value[])  \
    {                                                                                                              \
        CHECK("fmi2" #Kind, set ? MASK_Set : MASK_Get);                                                            \
        if (check_references(IN, "fmi2" #Kind, type_name, vr, nvr, value, set))                                    \
            return fmi2Error;                                                                                      \
        if (nvr == 0)                                                                                              \
            return fmi2OK;                                                                                         \
        return FORWARD("fmi2" #Kind, fmi2##Kind(IN->inner, vr, nvr, value));                                       \
    }
GET_SET(GetReal, "Real", fmi2Real, 0)
GET_SET(GetInteger, "Integer", fmi2Integer, 0)
GET_SET(GetBoolean, "Boolean", fmi2Boolean, 0)
GET_SET(GetString, "String", fmi2String, 0)
GET_SET(SetReal, "Real", const fmi2Real, 1)
GET_SET(SetInteger, "Integer", const fmi2Integer, 1)
GET_SET(SetBoolean, "Boolean", const fmi2Boolean, 1)
GET_SET(SetString, "String", const fmi2String, 1)

/* ---- FMU states: pythonfmu's, wrapped with the communication time --------------------------- */
static ShimState *our_state(Instance *in, const char *function, fmi2FMUstate state)
{
    ShimState *s = shim_state_lookup(in->states, state);
    if (!s)
        refuse(in, "%s: %p is not an FMU state of this instance (from its fmi2GetFMUstate or fmi2DeSerializeFMUstate, "
               "not yet freed)", function, state);
    return s;
}

/* The state machine state an FMU state taken now returns the instance to (fmi2SetFMUstate): a state
 * taken in StepFailed is the one before the refused step, one taken in Error the one before the Error */
static int taken_in(const Instance *in)
{
    int state = in->state == ErrorState ? in->before_error : in->state;
    return state == StepFailed ? StepComplete : state;
}

/* Hands pythonfmu's state got (taken at time, in the state machine state phase) to the host: in old, one of
 * the instance's states the host gave (updated: its previous pythonfmu state freed), else in a new one
 * written to *state. Returns status, or fmi2Error logged where out of memory. */
static fmi2Status hand_over(Instance *in, const char *function, fmi2Status status, fmi2FMUstate got, double time,
                            int phase, ShimState *old, fmi2FMUstate *state)
{
    if (old) {
        fmi2FMUstate previous = old->inner;
        if (previous)
            inner.fmi2FreeFMUstate(in->inner, &previous);
        old->inner = got;
    } else if (!(old = shim_state_add(&in->states, got, time))) {
        inner.fmi2FreeFMUstate(in->inner, &got);
        return refuse(in, "%s: out of memory", function);
    }
    old->time = time;
    old->phase = phase;
    *state = old;
    return status;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    CHECK("fmi2GetFMUstate", MASK_GetFMUstate);
    if (!state)
        return refuse(IN, "fmi2GetFMUstate: FMUstate is NULL");
    ShimState *old = NULL;
    if (*state && !(old = our_state(IN, "fmi2GetFMUstate", *state)))  /* FMI 2.0: a non-NULL state is updated */
        return fmi2Error;
    fmi2FMUstate got = NULL;
    fmi2Status status = FORWARD("fmi2GetFMUstate", fmi2GetFMUstate(IN->inner, &got));
    if (status > fmi2Warning)
        return status;
    return hand_over(IN, "fmi2GetFMUstate", status, got, IN->time, taken_in(IN), old, state);
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    CHECK("fmi2SetFMUstate", MASK_StateData);
    ShimState *s = our_state(IN, "fmi2SetFMUstate", state);
    if (!s)
        return fmi2Error;
    fmi2Status status = FORWARD("fmi2SetFMUstate", fmi2SetFMUstate(IN->inner, s->inner));
    if (status <= fmi2Warning) {
        IN->time = s->time;
        IN->time_origin = TIME_STATE;
        /* the instance returns to the state machine state the FMU state was taken in, as the Reference
         * FMUs' do (fmusim restores a running state right after fmi2Instantiate): a deserialized state
         * is a running instance's (StepComplete); out of StepFailed and out of Error */
        IN->state = s->phase ? s->phase : StepComplete;
    }
    return status;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    if (!c || !state || !*state)
        return fmi2OK;
    CHECK("fmi2FreeFMUstate", MASK_StateData);
    /* fmusim (v0.0.39, --final-fmu-state-file) passes the state itself instead of its address: one of our
     * states is recognised by its pointer alone (never read), freed, and the host told so (a Warning) */
    ShimState *s = shim_state_lookup(IN->states, (const void *)state);
    int given_state = s != NULL;
    if (given_state)
        shim_log_text(&IN->log, fmi2Warning, "logStatusWarning", "fmi2FreeFMUstate: given an FMU state instead of its "
                      "address (an fmi2FMUstate*): that state is freed");
    else if (!(s = our_state(IN, "fmi2FreeFMUstate", *state)))
        return fmi2Error;
    fmi2FMUstate inner_state = s->inner;
    fmi2Status status = fmi2OK;
    if (inner_state) {
        begin(IN, "fmi2FreeFMUstate");
        status = finish(IN, inner.fmi2FreeFMUstate(IN->inner, &inner_state), 0, 0);
    }
    shim_state_remove(&IN->states, s);
    if (!given_state)
        *state = NULL;
    return status;
}

static fmi2Status payload_size(Instance *in, ShimState *s, size_t *size)
{
    begin(in, "fmi2SerializedFMUstateSize");
    return finish(in, inner.fmi2SerializedFMUstateSize(in->inner, s->inner, size), 0, 0);
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    CHECK("fmi2SerializedFMUstateSize", MASK_StateData);
    if (!size)
        return refuse(IN, "fmi2SerializedFMUstateSize: size is NULL");
    ShimState *s = our_state(IN, "fmi2SerializedFMUstateSize", state);
    if (!s)
        return fmi2Error;
    size_t n = 0;
    fmi2Status status = payload_size(IN, s, &n);
    if (status <= fmi2Warning)
        *size = n + shim_state_header_size();
    return status;
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    CHECK("fmi2SerializeFMUstate", MASK_StateData);
    ShimState *s = our_state(IN, "fmi2SerializeFMUstate", state);
    if (!s)
        return fmi2Error;
    if (!bytes && size > 0)
        return refuse(IN, "fmi2SerializeFMUstate: serializedState is NULL");
    size_t n = 0;
    fmi2Status status = payload_size(IN, s, &n);
    if (status > fmi2Warning)
        return status;
    if (size < n + shim_state_header_size())
        return refuse(IN, "fmi2SerializeFMUstate: size = %lu is less than fmi2SerializedFMUstateSize's %lu",
                      (unsigned long)size, (unsigned long)(n + shim_state_header_size()));
    begin(IN, "fmi2SerializeFMUstate");
    status = finish(IN, inner.fmi2SerializeFMUstate(IN->inner, s->inner, bytes + shim_state_header_size(), n), 0, 0);
    if (status <= fmi2Warning)
        shim_state_header_write((unsigned char *)bytes, IN->guid, s->time, n);
    return status;
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    CHECK("fmi2DeSerializeFMUstate", MASK_StateData);
    if (!state)
        return refuse(IN, "fmi2DeSerializeFMUstate: FMUstate is NULL");
    char why[256];
    double time = 0.0;
    const unsigned char *payload = NULL;
    size_t n = 0;
    if (shim_state_header_check((const unsigned char *)bytes, size, IN->guid, &time, &payload, &n, why, sizeof why))
        return refuse(IN, "fmi2DeSerializeFMUstate: %lu bytes are not a state of this FMU (%s)", (unsigned long)size, why);
    ShimState *old = *state ? shim_state_lookup(IN->states, *state) : NULL;
    fmi2FMUstate got = NULL;
    begin(IN, "fmi2DeSerializeFMUstate");
    fmi2Status status = finish(IN, inner.fmi2DeSerializeFMUstate(IN->inner, (const fmi2Byte *)payload, n, &got), 0, 0);
    if (status > fmi2Warning)
        return status;
    return hand_over(IN, "fmi2DeSerializeFMUstate", status, got, time, 0, old, state);  /* 0: a running instance's */
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const fmi2Real dz[],
                                               fmi2Real du[])
{
    CHECK("fmi2GetDirectionalDerivative", MASK_GetDirectionalDerivative);
    return FORWARD("fmi2GetDirectionalDerivative", fmi2GetDirectionalDerivative(IN->inner, u, nu, z, nz, dz, du));
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[])
{
    CHECK("fmi2SetRealInputDerivatives", MASK_SetRealInputDerivatives);
    return FORWARD("fmi2SetRealInputDerivatives", fmi2SetRealInputDerivatives(IN->inner, vr, nvr, order, value));
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[])
{
    CHECK("fmi2GetRealOutputDerivatives", MASK_GetRealOutputDerivatives);
    return FORWARD("fmi2GetRealOutputDerivatives", fmi2GetRealOutputDerivatives(IN->inner, vr, nvr, order, value));
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                             fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    CHECK("fmi2DoStep", MASK_DoStep);
    char a[32], b[32];
    if (!(communicationStepSize > 0) || communicationStepSize - communicationStepSize != 0)
        return refuse(IN, "fmi2DoStep: communicationStepSize = %s must be > 0", shim_double(a, communicationStepSize));
    if (!shim_same_time(IN->time, currentCommunicationPoint)) {
        static const char *origin[] = {
            [TIME_START] = "but the experiment starts at %s (fmi2SetupExperiment's startTime)",
            [TIME_STEP] = "but the last step ended at %s",
            [TIME_DISCARD] = "but the refused step started at %s (retry it from there, possibly with other inputs)",
            [TIME_STATE] = "but the state set by fmi2SetFMUstate is at %s",
        };
        char where[160];
        shim_format(where, sizeof where, origin[IN->time_origin], shim_double(b, IN->time));
        return refuse(IN, "fmi2DoStep: currentCommunicationPoint = %s %s%s", shim_double(a, currentCommunicationPoint),
                      where, currentCommunicationPoint < IN->time && IN->time_origin == TIME_STEP
                                 ? " (restore a state with fmi2SetFMUstate to go back)" : "");
    }
    begin(IN, "fmi2DoStep");
    fmi2Status status = finish(IN, inner.fmi2DoStep(IN->inner, currentCommunicationPoint, communicationStepSize,
                                                    noSetFMUStatePriorToCurrentPoint), 1, 1);
    if (status <= fmi2Warning) {
        IN->time = currentCommunicationPoint + communicationStepSize;
        IN->time_origin = TIME_STEP;
        if (IN->state != ErrorState)
            IN->state = StepComplete;
    } else if (status == fmi2Discard) {
        IN->time = currentCommunicationPoint;
        IN->time_origin = TIME_DISCARD;
        if (IN->state != ErrorState)
            IN->state = StepFailed;
    }
    return status;
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c)
{
    CHECK("fmi2CancelStep", MASK_CancelStep);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    CHECK("fmi2GetStatus", MASK_Status);
    if (s == fmi2DoStepStatus && value) {  /* steps are synchronous: never pending */
        *value = IN->state == ErrorState ? fmi2Error : fmi2OK;
        return fmi2OK;
    }
    return fmi2Discard;  /* FMI 2.0: Discard when the status is not available */
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    CHECK("fmi2GetRealStatus", MASK_Status);
    if (!value)
        return refuse(IN, "fmi2GetRealStatus: value is NULL");
    begin(IN, "fmi2GetRealStatus");
    return finish(IN, inner.fmi2GetRealStatus(IN->inner, s, value), 1, 0);
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    CHECK("fmi2GetIntegerStatus", MASK_Status);
    (void)s; (void)value;
    return fmi2Discard;
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    CHECK("fmi2GetBooleanStatus", MASK_Status);
    if (s == fmi2Terminated && value) {
        *value = IN->state == ErrorState ? 1 : 0;
        return fmi2OK;
    }
    return fmi2Discard;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    CHECK("fmi2GetStringStatus", MASK_Status);
    (void)s; (void)value;
    return fmi2Discard;
}
