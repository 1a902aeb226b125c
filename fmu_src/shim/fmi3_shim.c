/* The FMI 3.0 binary of our FMUs: a layer in front of pythonfmu3's that enforces the FMI 3.0
 * co-simulation standard.
 *
 * build_fmu.py compiles this file as binaries/x86_64-linux/<modelIdentifier>.so and moves
 * pythonfmu3's binary beside it as pythonfmu-export.so (fmu_build/win64.py: binaries/x86_64-windows/
 * <modelIdentifier>.dll with python_runtime_win.c, beside pythonfmu-export.dll). The host gets an
 * instance of ours, which holds pythonfmu3's; this layer adds:
 *
 * 1. Python. Before pythonfmu3's binary is loaded, python_runtime_load() starts the Python the
 *    FMU carries (or the one named in resources/python_runtime.txt); a system below the FMU's
 *    glibc floor, or a Python that cannot start, is reported through the host's logMessage by
 *    fmi3InstantiateCoSimulation, which returns NULL. pythonfmu3's binary is not linked to libpython:
 *    without this layer a C host fails with "undefined symbol: _Py_NoneStruct".
 *
 * 2. Exit. pythonfmu3's teardown writes into freed memory at process exit, as pythonfmu's
 *    does; python_runtime_open_binary() empties its interpreter holder first (release_binary
 *    in python_runtime.c).
 *
 * 3. The state machine of co-simulation (FMI 3.0): Instantiated, InitializationMode, StepMode,
 *    ConfigurationMode / ReconfigurationMode (only for an FMU with structural parameters),
 *    Terminated, and Error (after an Error of the model). EventMode needs hasEventMode, which these
 *    FMUs do not declare: eventModeUsed = true is refused at instantiation, and the event-mode,
 *    model-exchange, scheduled-execution and clock functions are refused. A call the standard
 *    forbids returns fmi3Error with one line in the host's log naming the function and the reason,
 *    is not passed to pythonfmu3 and changes nothing: the instance stays in its state.
 *
 * 4. Variables. resources/fmi_variables.tsv (written by the build, read with shim_rules.h) gives each
 *    value reference's type, causality, variability and number of values (the product of its
 *    Dimension starts: nValues is checked against it, except for an array a structural parameter
 *    sizes). An unknown value reference, a value reference
 *    of another type, nValues not matching the variables, a NULL array, and a set the standard
 *    forbids (an output, a calculated parameter, the independent variable, a constant, a fixed
 *    parameter after initialization, a structural parameter outside ConfigurationMode) are refused.
 *
 * 5. Steps. fmi3DoStep needs communicationStepSize > 0 and currentCommunicationPoint at the
 *    instance's time: the startTime of fmi3EnterInitializationMode, then the end of the last
 *    successful step (a Discard leaves it at the start of the refused step), or the time of the
 *    state set by fmi3SetFMUState, to shim_same_time's tolerance.
 *
 * 6. Statuses. pythonfmu3 returns fmi3OK whatever the model logged; here a call returns the worst
 *    status logged during it (an Error logged by fmi3ExitInitializationMode makes it return
 *    fmi3Error), a Warning is logged and the call stays fmi3OK (fmusim ends a run on fmi3Warning),
 *    and a Discard is a status of fmi3DoStep only. After an Error the instance is in state Error:
 *    getters, the FMU state functions, fmi3Reset and fmi3FreeInstance only. A Python exception,
 *    which pythonfmu3 reports as fmi3Fatal after releasing its Python object, is fmi3Error with its
 *    message; that instance then takes fmi3FreeInstance only.
 *
 * 7. Logging. pythonfmu3 always logs to this layer, which passes Error messages to the host always
 *    and the others when the host asked for them (loggingOn, fmi3SetDebugLogging and its categories).
 *
 * 8. FMU states. The host gets a ShimState (shim_rules.h) that holds pythonfmu3's state and the
 *    communication time it was taken at; a pointer that is not a live state of this instance is
 *    refused without being read. A serialized state carries shim_rules.h's header (magic, format
 *    version, the payload's CRC-32, the instantiation token's hash, the time, the payload length),
 *    checked by fmi3DeserializeFMUState, which names the check that failed: a corrupted payload is
 *    refused before it reaches pythonfmu3.
 */
#include "shim_platform.h"  /* first: glibc_compat.h on Linux, windows.h on Windows */
#include "python_runtime.h"
#include "shim_rules.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FMI3_Export SHIM_EXPORT
#include "fmi3/fmi3Functions.h"

#define INNER_BINARY SHIM_INNER_BINARY

/* pythonfmu3's functions this layer calls: X(name, (parameters), (arguments)). */
#define FMI3_INNER(X) \
    X(fmi3EnterInitializationMode, (fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime), (instance, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime)) \
    X(fmi3ExitInitializationMode, (fmi3Instance instance), (instance)) \
    X(fmi3Terminate, (fmi3Instance instance), (instance)) \
    X(fmi3Reset, (fmi3Instance instance), (instance)) \
    X(fmi3GetFloat32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetFloat64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetInt8, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int8 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetUInt8, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt8 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetInt16, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int16 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetUInt16, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt16 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetInt32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetUInt32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetInt64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetUInt64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetBoolean, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Boolean values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetString, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3String values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3GetBinary, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, size_t valueSizes[], fmi3Binary values[], size_t nValues), (instance, valueReferences, nValueReferences, valueSizes, values, nValues)) \
    X(fmi3SetFloat32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetFloat64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetInt8, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int8 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetUInt8, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt8 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetInt16, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int16 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetUInt16, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt16 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetInt32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetUInt32, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt32 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetInt64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetUInt64, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetBoolean, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Boolean values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetString, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3String values[], size_t nValues), (instance, valueReferences, nValueReferences, values, nValues)) \
    X(fmi3SetBinary, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[], size_t nValues), (instance, valueReferences, nValueReferences, valueSizes, values, nValues)) \
    X(fmi3GetFMUState, (fmi3Instance instance, fmi3FMUState* FMUState), (instance, FMUState)) \
    X(fmi3SetFMUState, (fmi3Instance instance, fmi3FMUState FMUState), (instance, FMUState)) \
    X(fmi3FreeFMUState, (fmi3Instance instance, fmi3FMUState* FMUState), (instance, FMUState)) \
    X(fmi3SerializedFMUStateSize, (fmi3Instance instance, fmi3FMUState FMUState, size_t* size), (instance, FMUState, size)) \
    X(fmi3SerializeFMUState, (fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size), (instance, FMUState, serializedState, size)) \
    X(fmi3DeserializeFMUState, (fmi3Instance instance, const fmi3Byte serializedState[], size_t size, fmi3FMUState* FMUState), (instance, serializedState, size, FMUState)) \
    X(fmi3DoStep, (fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime), (instance, currentCommunicationPoint, communicationStepSize, noSetFMUStatePriorToCurrentPoint, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime))

#define MEMBER(name, params, args) fmi3Status(*name) params;
static struct {
    FMI3_INNER(MEMBER)
    fmi3InstantiateCoSimulationTYPE *fmi3InstantiateCoSimulation;
    fmi3FreeInstanceTYPE *fmi3FreeInstance;
} inner;
static int inner_loaded = 0;
static pthread_mutex_t inner_lock = PTHREAD_MUTEX_INITIALIZER;

#define RESOLVE_NAME(name)                                                                \
    if (status == 0 && !(*(void **)&inner.name = dlsym(handle, #name))) {                 \
        snprintf(err, size, "%s has no function %s", INNER_BINARY, #name);                 \
        status = -1;                                                                      \
    }
#define RESOLVE(name, params, args) RESOLVE_NAME(name)

/* Load Python, then pythonfmu3's binary and its functions, once. 0, or -1 with a message. */
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
            FMI3_INNER(RESOLVE)
            RESOLVE_NAME(fmi3InstantiateCoSimulation)
            RESOLVE_NAME(fmi3FreeInstance)
        }
        inner_loaded = (status == 0);
    }
    pthread_mutex_unlock(&inner_lock);
    return status;
}

/* ---- states of the co-simulation state machine ------------------------------------------- */
enum {
    M_INSTANTIATED = 1 << 0,
    M_INITIALIZATION = 1 << 1,
    M_EVENT = 1 << 2,
    M_STEP = 1 << 3,
    M_CONFIGURATION = 1 << 4,
    M_RECONFIGURATION = 1 << 5,
    M_TERMINATED = 1 << 6,
    M_ERROR = 1 << 7,
};
static const char *const MODE_NAMES[] = {"Instantiated", "InitializationMode", "EventMode", "StepMode",
                                         "ConfigurationMode", "ReconfigurationMode", "Terminated", "Error"};
#define N_MODES 8
#define M_ANY ((1 << N_MODES) - 1)
/* getters: every state (in Error for diagnosis); setters: the variable decides (may_set) */
#define MASK_GET M_ANY
#define MASK_SET (M_INSTANTIATED | M_INITIALIZATION | M_EVENT | M_STEP | M_CONFIGURATION | M_RECONFIGURATION)
#define MASK_TERMINATE (M_EVENT | M_STEP | M_RECONFIGURATION)

static const char *mode_name(int mode)
{
    for (int i = 0; i < N_MODES; i++)
        if (mode == 1 << i)
            return MODE_NAMES[i];
    return "?";
}

/* "StepMode" or "Instantiated, InitializationMode" */
static void mode_list(int mask, char *buf, size_t size)
{
    size_t n = 0;
    buf[0] = '\0';
    for (int i = 0; i < N_MODES && n + 1 < size; i++)
        if (mask & (1 << i)) {
            shim_format(buf + n, size - n, "%s%s", n ? ", " : "", MODE_NAMES[i]);
            n = strlen(buf);
        }
}

/* ---- one instance ------------------------------------------------------------------------ */
typedef struct {
    fmi3Instance inner;                /* pythonfmu3's instance */
    int mode;                          /* M_... */
    int mode_before_error;             /* where fmi3SetFMUState returns to from Error */
    int mode_before_reconfiguration;   /* where fmi3ExitConfigurationMode returns to */
    int broken;                        /* pythonfmu3 lost its Python object: fmi3FreeInstance only */
    const char *call;                  /* the function being called (for pythonfmu3's exception messages) */
    fmi3InstanceEnvironment host_environment;
    fmi3LogMessageCallback host_log;
    char *name;
    char *token;                       /* instantiationToken: in every serialized state's header */
    ShimLog log;                       /* to the host's logMessage: loggingOn, fmi3SetDebugLogging's categories */
    ShimVariables variables;           /* resources/fmi_variables.tsv */
    int structural, tunable_structural;
    double time;                       /* where the next step must start */
    fmi3Status logged;                 /* worst status pythonfmu3 logged during the current call */
    ShimState *states;                 /* FMU states handed to the host, not yet freed */
} Instance;

/* The instance's log sink (shim_rules.h) */
static void log_sink(void *layer, int status, const char *category, const char *text)
{
    const Instance *in = (const Instance *)layer;
    in->host_log(in->host_environment, (fmi3Status)status, category ? category : "", text);
}

/* pythonfmu3's messages come here (its logger's environment is our instance) */
static void shim_log(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                     fmi3String message)
{
    Instance *in = (Instance *)environment;
    if (!in || !message)
        return;
    if (status > in->logged)
        in->logged = status;
    if (status == fmi3Fatal) {  /* pythonfmu3: a Python exception; an Error of the call (see finish) */
        const char *prefix = "Fatal py exception encountered: ";
        if (!strncmp(message, prefix, strlen(prefix)))
            message += strlen(prefix);
        char text[4096];
        shim_format(text, sizeof text, "%s: the model's Python code failed: %s", in->call ? in->call : "fmi3", message);
        shim_log_text(&in->log, fmi3Error, "logStatusError", text);
        return;
    }
    shim_log_text(&in->log, status, category, message);
}

/* A caller's mistake: one Error line in the host's log; returns fmi3Error, changes nothing. */
#define refuse(in, ...) ((fmi3Status)shim_refuse(&(in)->log, __VA_ARGS__))

static void enter_error(Instance *in)
{
    if (in->mode != M_ERROR)
        in->mode_before_error = in->mode;
    in->mode = M_ERROR;
}

/* May function fn be called now (state in mask)? 1, or 0 after logging why not. */
static int allowed(Instance *in, const char *fn, int mask)
{
    if (!in || !python_runtime_binary_open())  /* pythonfmu3's binary is released at process exit */
        return 0;
    in->call = fn;
    if (in->broken) {
        refuse(in, "%s: not possible: the model's Python code failed in this instance (see the Error logged "
                   "before); only fmi3FreeInstance is", fn);
        return 0;
    }
    if (!(in->mode & mask)) {
        char list[256];
        mode_list(mask, list, sizeof list);
        refuse(in, "%s: not allowed in state %s (allowed: %s)", fn, mode_name(in->mode), list[0] ? list : "none");
        return 0;
    }
    return 1;
}

static void begin(Instance *in) { in->logged = fmi3OK; }

/* The status of a forwarded call: pythonfmu3's, raised to the worst status logged during it (a
 * logged Discard only where FMI 3.0 allows Discard: fmi3DoStep; a Warning is for the log only). */
static fmi3Status finish(Instance *in, fmi3Status status, int discard_allowed)
{
    fmi3Status logged = in->logged;
    in->logged = fmi3OK;
    if (status == fmi3Fatal) {  /* a Python exception: pythonfmu3 has released its Python object */
        in->broken = 1;
        enter_error(in);
        return fmi3Error;
    }
    if (logged == fmi3Discard && !discard_allowed)
        logged = fmi3Warning;  /* as the FMI 2.0 layer: the refusal is in the log */
    else if (logged == fmi3Warning)
        logged = fmi3OK;
    if (status == fmi3Warning)
        status = fmi3OK;
    if (logged > status)
        status = logged;
    if (status == fmi3Discard && !discard_allowed)
        status = fmi3Warning;
    if (status >= fmi3Error) {
        status = fmi3Error;
        enter_error(in);
    }
    return status;
}

/* ---- variables ----------------------------------------------------------------------------- */
static const char *variable_name(const ShimVariable *v)
{
    return v->name ? v->name : "?";
}

/* May v be set in the instance's state? 1, or 0 with the reason. */
static int may_set(const Instance *in, const ShimVariable *v, const char *fn, char *why, size_t size)
{
    int tunable = !strcmp(v->variability, "tunable");
    if (!strcmp(v->causality, "structuralParameter")) {
        int mask = M_CONFIGURATION | (tunable ? M_RECONFIGURATION : 0);
        if (in->mode & mask)
            return 1;
        shim_format(why, size, "is a %sstructural parameter: it can be set only in ConfigurationMode%s (now %s)",
                    tunable ? "tunable " : "", tunable ? " or ReconfigurationMode" : "", mode_name(in->mode));
        return 0;
    }
    if (in->mode & (M_CONFIGURATION | M_RECONFIGURATION)) {
        shim_format(why, size, "is not a structural parameter: it cannot be set in %s", mode_name(in->mode));
        return 0;
    }
    int phase = in->mode == M_INSTANTIATED ? SHIM_BEFORE_INITIALIZATION
                : in->mode == M_INITIALIZATION ? SHIM_INITIALIZING : SHIM_RUNNING;
    (void)fn;
    return shim_may_set(v, phase, "fmi3ExitInitializationMode", why, size);
}

/* Check the value references and arrays of a get or set of type `type`; 1, or 0 after logging. */
static int check_values(Instance *in, const char *fn, const char *type, const fmi3ValueReference vrs[],
                        size_t nvr, const void *values, size_t n_values, int setting)
{
    if (nvr > 0 && !vrs) {
        refuse(in, "%s: valueReferences is NULL, nValueReferences = %lu", fn, (unsigned long)nvr);
        return 0;
    }
    if (n_values > 0 && !values) {
        refuse(in, "%s: values is NULL, nValues = %lu", fn, (unsigned long)n_values);
        return 0;
    }
    size_t total = 0;
    int known = 1;
    for (size_t i = 0; i < nvr; i++) {
        const ShimVariable *v = shim_variable_find(&in->variables, NULL, vrs[i]);
        if (!v) {
            refuse(in, "%s: value reference %u is not a variable of this FMU", fn, vrs[i]);
            return 0;
        }
        if (strcmp(v->type, type)) {
            refuse(in, "%s: %s (value reference %u) is of type %s, not %s", fn, variable_name(v), vrs[i], v->type,
                   type);
            return 0;
        }
        char why[256];
        if (setting && !may_set(in, v, fn, why, sizeof why)) {
            refuse(in, "%s: %s (value reference %u) %s", fn, variable_name(v), vrs[i], why);
            return 0;
        }
        size_t count = v->n_values;  /* 0: sized by a structural parameter, not checked */
        if (count == 0)
            known = 0;
        total += count;
    }
    if (known && total != n_values) {
        refuse(in, "%s: nValues = %lu, but the %lu value reference%s ha%s %lu value%s", fn, (unsigned long)n_values,
               (unsigned long)nvr, nvr == 1 ? "" : "s", nvr == 1 ? "s" : "ve", (unsigned long)total,
               total == 1 ? "" : "s");
        return 0;
    }
    return 1;
}

#undef IN  /* windows.h defines IN as nothing */
#define IN ((Instance *)instance)

/* ---- getting and setting values ------------------------------------------------------------ */
#define GETTER(T)                                                                                         \
    FMI3_Export fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],  \
                                      size_t nValueReferences, fmi3##T values[], size_t nValues)          \
    {                                                                                                     \
        if (!allowed(IN, "fmi3Get" #T, MASK_GET) ||                                                       \
            !check_values(IN, "fmi3Get" #T, #T, valueReferences, nValueReferences, values, nValues, 0))   \
            return fmi3Error;                                                                             \
        if (nValueReferences == 0)                                                                        \
            return fmi3OK;                                                                                \
        begin(IN);                                                                                        \
        return finish(IN, inner.fmi3Get##T(IN->inner, valueReferences, nValueReferences, values, nValues), 0); \
    }
#define SETTER(T)                                                                                         \
    FMI3_Export fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],  \
                                      size_t nValueReferences, const fmi3##T values[], size_t nValues)    \
    {                                                                                                     \
        if (!allowed(IN, "fmi3Set" #T, MASK_SET) ||                                                       \
            !check_values(IN, "fmi3Set" #T, #T, valueReferences, nValueReferences, values, nValues, 1))   \
            return fmi3Error;                                                                             \
        if (nValueReferences == 0)                                                                        \
            return fmi3OK;                                                                                \
        begin(IN);                                                                                        \
        return finish(IN, inner.fmi3Set##T(IN->inner, valueReferences, nValueReferences, values, nValues), 0); \
    }
#define VALUE_TYPES(X) X(Float32) X(Float64) X(Int8) X(UInt8) X(Int16) X(UInt16) X(Int32) X(UInt32) X(Int64) \
    X(UInt64) X(Boolean) X(String)
VALUE_TYPES(GETTER)
VALUE_TYPES(SETTER)

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    if (!allowed(IN, "fmi3GetBinary", MASK_GET) ||
        !check_values(IN, "fmi3GetBinary", "Binary", valueReferences, nValueReferences, values, nValues, 0))
        return fmi3Error;
    if (nValues > 0 && !valueSizes)
        return refuse(IN, "fmi3GetBinary: valueSizes is NULL, nValues = %lu", (unsigned long)nValues);
    if (nValueReferences == 0)
        return fmi3OK;
    begin(IN);
    return finish(IN, inner.fmi3GetBinary(IN->inner, valueReferences, nValueReferences, valueSizes, values, nValues), 0);
}

FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[],
                                     size_t nValues)
{
    if (!allowed(IN, "fmi3SetBinary", MASK_SET) ||
        !check_values(IN, "fmi3SetBinary", "Binary", valueReferences, nValueReferences, values, nValues, 1))
        return fmi3Error;
    if (nValues > 0 && !valueSizes)
        return refuse(IN, "fmi3SetBinary: valueSizes is NULL, nValues = %lu", (unsigned long)nValues);
    if (nValueReferences == 0)
        return fmi3OK;
    begin(IN);
    return finish(IN, inner.fmi3SetBinary(IN->inner, valueReferences, nValueReferences, valueSizes, values, nValues), 0);
}

/* ---- functions these FMUs do not have -------------------------------------------------------- */
/* clocks: these FMUs have none, so every value reference is refused */
static fmi3Status no_clocks(Instance *in, const char *fn, const fmi3ValueReference vrs[], size_t nvr)
{
    if (!allowed(in, fn, M_ANY))
        return fmi3Error;
    if (nvr > 0 && !vrs)
        return refuse(in, "%s: valueReferences is NULL, nValueReferences = %lu", fn, (unsigned long)nvr);
    if (nvr > 0)
        return refuse(in, "%s: value reference %u is not a clock of this FMU (it has none)", fn, vrs[0]);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Clock values[])
{
    (void)values;
    return no_clocks(IN, "fmi3GetClock", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Clock values[])
{
    (void)values;
    return no_clocks(IN, "fmi3SetClock", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences, fmi3Float64 intervals[],
                                              fmi3IntervalQualifier qualifiers[])
{
    (void)intervals, (void)qualifiers;
    return no_clocks(IN, "fmi3GetIntervalDecimal", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                               fmi3IntervalQualifier qualifiers[])
{
    (void)counters, (void)resolutions, (void)qualifiers;
    return no_clocks(IN, "fmi3GetIntervalFraction", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)shifts;
    return no_clocks(IN, "fmi3GetShiftDecimal", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)counters, (void)resolutions;
    return no_clocks(IN, "fmi3GetShiftFraction", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                              size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)intervals;
    return no_clocks(IN, "fmi3SetIntervalDecimal", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                               size_t nValueReferences, const fmi3UInt64 counters[],
                                               const fmi3UInt64 resolutions[])
{
    (void)counters, (void)resolutions;
    return no_clocks(IN, "fmi3SetIntervalFraction", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)shifts;
    return no_clocks(IN, "fmi3SetShiftDecimal", valueReferences, nValueReferences);
}
FMI3_Export fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                            size_t nValueReferences, const fmi3UInt64 counters[],
                                            const fmi3UInt64 resolutions[])
{
    (void)counters, (void)resolutions;
    return no_clocks(IN, "fmi3SetShiftFraction", valueReferences, nValueReferences);
}

/* refused with `why`, whatever the state */
static fmi3Status unavailable(Instance *in, const char *fn, const char *why)
{
    if (!in || !python_runtime_binary_open())
        return fmi3Error;
    return refuse(in, "%s: %s", fn, why);
}
#define MODEL_EXCHANGE "a model-exchange function: this instance is a co-simulation one"
#define NO_EVENT_MODE "not allowed: the instance was created with eventModeUsed = false (this FMU has no event mode)"

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return unavailable(IN, "fmi3EnterEventMode", NO_EVENT_MODE);
}
FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    return unavailable(IN, "fmi3EnterStepMode", NO_EVENT_MODE);
}
FMI3_Export fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return unavailable(IN, "fmi3EvaluateDiscreteStates", NO_EVENT_MODE);
}
FMI3_Export fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                                fmi3Boolean *terminateSimulation,
                                                fmi3Boolean *nominalsOfContinuousStatesChanged,
                                                fmi3Boolean *valuesOfContinuousStatesChanged,
                                                fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate, (void)terminateSimulation, (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged, (void)nextEventTimeDefined, (void)nextEventTime;
    return unavailable(IN, "fmi3UpdateDiscreteStates", NO_EVENT_MODE);
}
FMI3_Export fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    return unavailable(IN, "fmi3EnterContinuousTimeMode", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    return unavailable(IN, "fmi3CompletedIntegratorStep", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    return unavailable(IN, "fmi3SetTime", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                               size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unavailable(IN, "fmi3SetContinuousStates", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                                         size_t nContinuousStates)
{
    (void)derivatives, (void)nContinuousStates;
    return unavailable(IN, "fmi3GetContinuousStateDerivatives", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[],
                                              size_t nEventIndicators)
{
    (void)eventIndicators, (void)nEventIndicators;
    return unavailable(IN, "fmi3GetEventIndicators", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[],
                                               size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unavailable(IN, "fmi3GetContinuousStates", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                                         size_t nContinuousStates)
{
    (void)nominals, (void)nContinuousStates;
    return unavailable(IN, "fmi3GetNominalsOfContinuousStates", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    return unavailable(IN, "fmi3GetNumberOfEventIndicators", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    return unavailable(IN, "fmi3GetNumberOfContinuousStates", MODEL_EXCHANGE);
}
FMI3_Export fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                                  fmi3Float64 activationTime)
{
    (void)clockReference, (void)activationTime;
    return unavailable(IN, "fmi3ActivateModelPartition", "a scheduled-execution function: this instance is a "
                                                         "co-simulation one");
}
FMI3_Export fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                    size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                                    const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                                    size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed, (void)sensitivity;
    (void)nSensitivity;
    return unavailable(IN, "fmi3GetDirectionalDerivative",
                       "this FMU provides no directional derivatives (providesDirectionalDerivatives is false)");
}
FMI3_Export fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                                const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                                size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed, (void)sensitivity;
    (void)nSensitivity;
    return unavailable(IN, "fmi3GetAdjointDerivative",
                       "this FMU provides no adjoint derivatives (providesAdjointDerivatives is false)");
}
FMI3_Export fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                                size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                                size_t nValues)
{
    (void)valueReferences, (void)nValueReferences, (void)orders, (void)values, (void)nValues;
    return unavailable(IN, "fmi3GetOutputDerivatives",
                       "this FMU provides no output derivatives (maxOutputDerivativeOrder is 0)");
}
FMI3_Export fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                                           size_t *nDependencies)
{
    (void)valueReference, (void)nDependencies;
    return unavailable(IN, "fmi3GetNumberOfVariableDependencies",
                       "this FMU provides no per-element dependencies (providesPerElementDependencies is false; "
                       "ModelStructure in modelDescription.xml lists the dependencies)");
}
FMI3_Export fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                                   size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                                   size_t elementIndicesOfIndependents[],
                                                   fmi3DependencyKind dependencyKinds[], size_t nDependencies)
{
    (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents;
    (void)dependencyKinds, (void)nDependencies;
    return unavailable(IN, "fmi3GetVariableDependencies",
                       "this FMU provides no per-element dependencies (providesPerElementDependencies is false; "
                       "ModelStructure in modelDescription.xml lists the dependencies)");
}

/* ---- life cycle ------------------------------------------------------------------------------- */
FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                                           const fmi3String categories[])
{
    if (!IN)
        return fmi3Error;
    if (nCategories > 0 && !categories)
        return refuse(IN, "fmi3SetDebugLogging: categories is NULL, nCategories = %lu", (unsigned long)nCategories);
    if (shim_log_set(&IN->log, loggingOn, nCategories, categories) != 0)
        return refuse(IN, "fmi3SetDebugLogging: out of memory");
    return fmi3OK;  /* pythonfmu3 logs everything to this layer, which filters */
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance, fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    const char *fn = "fmi3EnterInitializationMode";
    char a[32], b[32];
    if (!allowed(IN, fn, M_INSTANTIATED))
        return fmi3Error;
    if (!(startTime == startTime) || startTime > 1e300 || startTime < -1e300)
        return refuse(IN, "%s: startTime = %s must be finite", fn, shim_double(a, startTime));
    if (stopTimeDefined && !(stopTime >= startTime))
        return refuse(IN, "%s: stopTime = %s is before startTime = %s", fn, shim_double(a, stopTime),
                      shim_double(b, startTime));
    if (toleranceDefined && !(tolerance > 0))
        return refuse(IN, "%s: tolerance = %s must be > 0", fn, shim_double(a, tolerance));
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3EnterInitializationMode(IN->inner, toleranceDefined, tolerance, startTime,
                                                                     stopTimeDefined, stopTime), 0);
    if (status <= fmi3Warning) {
        IN->mode = M_INITIALIZATION;
        IN->time = startTime;
    }
    return status;
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    if (!allowed(IN, "fmi3ExitInitializationMode", M_INITIALIZATION))
        return fmi3Error;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3ExitInitializationMode(IN->inner), 0);
    if (status <= fmi3Warning)
        IN->mode = M_STEP;
    return status;
}

FMI3_Export fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    const char *fn = "fmi3EnterConfigurationMode";
    if (!allowed(IN, fn, M_INSTANTIATED | M_STEP))
        return fmi3Error;
    if (IN->mode == M_INSTANTIATED && !IN->structural)
        return refuse(IN, "%s: this FMU has no structural parameters", fn);
    if (IN->mode != M_INSTANTIATED && !IN->tunable_structural)
        return refuse(IN, "%s: this FMU has no tunable structural parameters (ReconfigurationMode)", fn);
    if (IN->mode == M_INSTANTIATED) {
        IN->mode = M_CONFIGURATION;
    } else {
        IN->mode_before_reconfiguration = IN->mode;
        IN->mode = M_RECONFIGURATION;
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    if (!allowed(IN, "fmi3ExitConfigurationMode", M_CONFIGURATION | M_RECONFIGURATION))
        return fmi3Error;
    IN->mode = IN->mode == M_CONFIGURATION ? M_INSTANTIATED : IN->mode_before_reconfiguration;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance instance)
{
    if (!allowed(IN, "fmi3Terminate", MASK_TERMINATE))
        return fmi3Error;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3Terminate(IN->inner), 0);
    if (status <= fmi3Warning)
        IN->mode = M_TERMINATED;
    return status;
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance instance)
{
    if (!allowed(IN, "fmi3Reset", M_ANY))
        return fmi3Error;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3Reset(IN->inner), 0);
    if (status <= fmi3Warning) {
        IN->mode = M_INSTANTIATED;
        IN->time = 0.0;
    }
    return status;
}

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                                  fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    const char *fn = "fmi3DoStep";
    char a[32], b[32];
    if (!allowed(IN, fn, M_STEP))
        return fmi3Error;
    double t = currentCommunicationPoint, h = communicationStepSize;
    if (!(h > 0) || h > 1e300)
        return refuse(IN, "%s: communicationStepSize = %s must be > 0 (and finite)", fn, shim_double(a, h));
    if (!shim_same_time(IN->time, t))
        return refuse(IN, "%s: currentCommunicationPoint = %s but the instance is at t = %s (the start time, the end "
                          "of the last successful step or the time of the state set last; fmi3SetFMUState goes back)",
                      fn, shim_double(a, t), shim_double(b, IN->time));
    /* pythonfmu3 leaves eventHandlingNeeded and earlyReturn unwritten */
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    fmi3Float64 last = t;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3DoStep(IN->inner, t, h, noSetFMUStatePriorToCurrentPoint, &event,
                                                    &terminate, &early, &last), 1);
    if (status <= fmi3Warning) {
        IN->time = t + h;
        last = t + h;
        terminate = fmi3False;
    } else if (status == fmi3Discard) {  /* refused, state kept: the next step starts at t again */
        last = t;
        terminate = fmi3False;
    } else {
        last = t;
        terminate = fmi3True;
    }
    if (eventHandlingNeeded)
        *eventHandlingNeeded = fmi3False;
    if (terminateSimulation)
        *terminateSimulation = terminate;
    if (earlyReturn)
        *earlyReturn = fmi3False;
    if (lastSuccessfulTime)
        *lastSuccessfulTime = last;
    return status;
}

/* ---- FMU states ---------------------------------------------------------------------------------- */
static ShimState *own_state(Instance *in, const char *fn, fmi3FMUState state)
{
    ShimState *s = shim_state_lookup(in->states, state);
    if (!s)
        refuse(in, "%s: FMUState %p is not a state of this instance (one from its fmi3GetFMUState or "
                   "fmi3DeserializeFMUState, not yet freed)", fn, state);
    return s;
}

FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    const char *fn = "fmi3GetFMUState";
    if (!allowed(IN, fn, M_ANY))
        return fmi3Error;
    if (!FMUState)
        return refuse(IN, "%s: FMUState is NULL", fn);
    ShimState *s = NULL;
    if (*FMUState && !(s = own_state(IN, fn, *FMUState)))
        return fmi3Error;
    fmi3FMUState taken = NULL;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3GetFMUState(IN->inner, &taken), 0);
    if (status > fmi3Warning || !taken)
        return status > fmi3Warning ? status : refuse(IN, "%s: the model returned no state", fn);
    if (s) {  /* FMI 3.0: a state given is updated */
        fmi3FMUState old = s->inner;
        inner.fmi3FreeFMUState(IN->inner, &old);
        s->inner = taken;
        s->time = IN->time;
    } else if (!(s = shim_state_add(&IN->states, taken, IN->time))) {
        inner.fmi3FreeFMUState(IN->inner, &taken);
        return refuse(IN, "%s: out of memory", fn);
    }
    s->phase = IN->mode == M_ERROR ? IN->mode_before_error : IN->mode;
    *FMUState = s;
    return status;
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    const char *fn = "fmi3SetFMUState";
    if (!allowed(IN, fn, M_ANY))
        return fmi3Error;
    ShimState *s = own_state(IN, fn, FMUState);
    if (!s)
        return fmi3Error;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3SetFMUState(IN->inner, s->inner), 0);
    if (status <= fmi3Warning) {
        /* back to the mode the state was taken in, at its time, as the Reference FMUs do (fmusim restores a
         * running state right after instantiation): a deserialized state is a running instance's (StepMode) */
        IN->mode = s->phase ? s->phase : M_STEP;
        IN->time = s->time;
    }
    return status;
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    if (!IN || !python_runtime_binary_open())
        return fmi3Error;
    if (!FMUState || !*FMUState)
        return fmi3OK;
    /* fmusim (v0.0.39, --final-fmu-state-file) passes the state itself instead of its address: one of our
     * states is recognised by its pointer alone (never read) and freed, the host told so (a Warning) */
    ShimState *s = shim_state_lookup(IN->states, (const void *)FMUState);
    int given_state = s != NULL;
    if (given_state) {
        shim_log_text(&IN->log, fmi3Warning, "logStatusWarning", "fmi3FreeFMUState: given an FMU state instead of "
                      "its address (an fmi3FMUState*): that state is freed");
    } else if (!(s = own_state(IN, "fmi3FreeFMUState", *FMUState)))
        return fmi3Error;
    fmi3FMUState taken = s->inner;
    begin(IN);
    IN->call = "fmi3FreeFMUState";
    fmi3Status status = inner.fmi3FreeFMUState(IN->inner, &taken);  /* a Py_DECREF: safe in a broken instance */
    IN->logged = fmi3OK;
    shim_state_remove(&IN->states, s);
    if (!given_state)
        *FMUState = NULL;
    return status == fmi3OK ? fmi3OK : fmi3Error;
}

/* the size of pythonfmu3's bytes of a state; 0, or -1 (status set) */
static int payload_size(Instance *in, ShimState *s, size_t *size, fmi3Status *status)
{
    *size = 0;
    begin(in);
    *status = finish(in, inner.fmi3SerializedFMUStateSize(in->inner, s->inner, size), 0);
    return *status <= fmi3Warning ? 0 : -1;
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    const char *fn = "fmi3SerializedFMUStateSize";
    if (!allowed(IN, fn, M_ANY))
        return fmi3Error;
    if (!size)
        return refuse(IN, "%s: size is NULL", fn);
    ShimState *s = own_state(IN, fn, FMUState);
    size_t n;
    fmi3Status status;
    if (!s || payload_size(IN, s, &n, &status) != 0)
        return fmi3Error;
    *size = n + shim_state_header_size();
    return status;
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                             size_t size)
{
    const char *fn = "fmi3SerializeFMUState";
    if (!allowed(IN, fn, M_ANY))
        return fmi3Error;
    ShimState *s = own_state(IN, fn, FMUState);
    size_t n;
    fmi3Status status;
    if (!s || payload_size(IN, s, &n, &status) != 0)
        return fmi3Error;
    if (size != n + shim_state_header_size())
        return refuse(IN, "%s: size = %lu, but this state takes %lu bytes (fmi3SerializedFMUStateSize)", fn,
                      (unsigned long)size, (unsigned long)(n + shim_state_header_size()));
    if (!serializedState)
        return refuse(IN, "%s: serializedState is NULL", fn);
    begin(IN);
    status = finish(IN, inner.fmi3SerializeFMUState(IN->inner, s->inner, serializedState + shim_state_header_size(),
                                                    n), 0);
    if (status <= fmi3Warning)
        shim_state_header_write((unsigned char *)serializedState, IN->token, s->time, n);
    return status;
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                               fmi3FMUState *FMUState)
{
    const char *fn = "fmi3DeserializeFMUState";
    if (!allowed(IN, fn, M_ANY))
        return fmi3Error;
    if (!FMUState)
        return refuse(IN, "%s: FMUState is NULL", fn);
    if (!serializedState && size > 0)
        return refuse(IN, "%s: serializedState is NULL, size = %lu", fn, (unsigned long)size);
    double time = 0;
    const unsigned char *payload = NULL;
    size_t n = 0;
    char why[256];
    if (shim_state_header_check((const unsigned char *)serializedState, size, IN->token, &time, &payload, &n, why,
                                sizeof why) != SHIM_STATE_OK)
        return refuse(IN, "%s: %lu bytes are not a state of this FMU (%s)", fn, (unsigned long)size, why);
    fmi3FMUState taken = NULL;
    begin(IN);
    fmi3Status status = finish(IN, inner.fmi3DeserializeFMUState(IN->inner, (const fmi3Byte *)payload, n, &taken), 0);
    if (status > fmi3Warning || !taken)
        return status > fmi3Warning ? status : refuse(IN, "%s: the model returned no state", fn);
    ShimState *s = shim_state_add(&IN->states, taken, time);
    if (!s) {
        inner.fmi3FreeFMUState(IN->inner, &taken);
        return refuse(IN, "%s: out of memory", fn);
    }
    *FMUState = s;
    return status;
}

/* ---- instances ----------------------------------------------------------------------------------- */
/* Windows: a resource folder pythonfmu3's DLL cannot use is refused with a message (python_runtime.h) */
#ifdef _WIN32
#define LOCATION_REFUSED(path) (python_runtime_check_location((path), err, sizeof err) != 0)
#else
#define LOCATION_REFUSED(path) 0
#endif

static void report(fmi3InstanceEnvironment environment, fmi3LogMessageCallback log, const char *err)
{
    if (log)
        log(environment, fmi3Error, "logStatusError", err);
    else
        fprintf(stderr, "%s\n", err);  /* a host without a logger: say it on stderr, not nowhere */
}

static void free_instance(Instance *in)
{
    if (!in)
        return;
    shim_variables_free(&in->variables);
    shim_log_free(&in->log);
    free(in->name);
    free(in->token);
    free(in);
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[], size_t nRequiredIntermediateVariables,
    fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3IntermediateUpdateCallback intermediateUpdate)
{
    char err[2048] = "";
    if (eventModeUsed) {
        report(instanceEnvironment, logMessage, "fmi3InstantiateCoSimulation: eventModeUsed = true, but this FMU "
                                                "has no event mode (hasEventMode is false)");
        return NULL;
    }
    if (!resourcePath) {
        report(instanceEnvironment, logMessage, "fmi3InstantiateCoSimulation: resourcePath is NULL: this FMU needs "
                                                "its resources folder");
        return NULL;
    }
    if (LOCATION_REFUSED(resourcePath) || load_inner(err, sizeof err) != 0) {
        report(instanceEnvironment, logMessage, err);
        return NULL;
    }
    Instance *in = (Instance *)calloc(1, sizeof *in);
    if (!in) {
        report(instanceEnvironment, logMessage, "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    if (shim_variables_load(&in->variables, resourcePath, err, sizeof err) != 0) {
        char text[2200];
        shim_format(text, sizeof text, "fmi3InstantiateCoSimulation: %s", err);
        report(instanceEnvironment, logMessage, text);
        free_instance(in);
        return NULL;
    }
    for (size_t i = 0; i < in->variables.n; i++)
        if (!strcmp(in->variables.items[i].causality, "structuralParameter")) {
            in->structural = 1;
            if (!strcmp(in->variables.items[i].variability, "tunable"))
                in->tunable_structural = 1;
        }
    in->name = strdup(instanceName ? instanceName : "");
    in->token = strdup(instantiationToken ? instantiationToken : "");
    in->host_environment = instanceEnvironment;
    in->host_log = logMessage;
    in->log.sink = logMessage ? log_sink : NULL;
    in->log.layer = in;
    in->log.on = loggingOn;
    in->mode = M_INSTANTIATED;
    if (!in->name || !in->token) {
        report(instanceEnvironment, logMessage, "fmi3InstantiateCoSimulation: out of memory");
        free_instance(in);
        return NULL;
    }
    begin(in);
    in->call = "fmi3InstantiateCoSimulation";
    /* pythonfmu3 always logs to us (its logger's environment is our instance); we filter */
    in->inner = inner.fmi3InstantiateCoSimulation(instanceName, instantiationToken, resourcePath, visible, fmi3True,
                                                  eventModeUsed, earlyReturnAllowed, requiredIntermediateVariables,
                                                  nRequiredIntermediateVariables, (fmi3InstanceEnvironment)in,
                                                  shim_log, intermediateUpdate);
    if (!in->inner) {
        free_instance(in);
        return NULL;
    }
    in->logged = fmi3OK;
    return in;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                                      fmi3String resourcePath, fmi3Boolean visible,
                                                      fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                                      fmi3LogMessageCallback logMessage)
{
    (void)instanceName, (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    report(instanceEnvironment, logMessage, "fmi3InstantiateModelExchange: this FMU is for co-simulation only "
                                            "(fmi3InstantiateCoSimulation)");
    return NULL;
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName, (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    (void)clockUpdate, (void)lockPreemption, (void)unlockPreemption;
    report(instanceEnvironment, logMessage, "fmi3InstantiateScheduledExecution: this FMU is for co-simulation only "
                                            "(fmi3InstantiateCoSimulation)");
    return NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance)
{
    Instance *in = IN;
    if (!in)
        return;
    int open = inner_loaded && python_runtime_binary_open();
    while (in->states) {  /* the states the host did not free */
        ShimState *s = in->states;
        fmi3FMUState taken = s->inner;
        if (open)
            inner.fmi3FreeFMUState(in->inner, &taken);
        shim_state_remove(&in->states, s);
    }
    /* a broken instance is left as it is: pythonfmu3 would release its Python object a second time */
    if (open && !in->broken)
        inner.fmi3FreeInstance(in->inner);
    free_instance(in);
}
