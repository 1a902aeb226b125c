/* The FMI 3.0 binary of our FMUs on Linux: a thin layer in front of pythonfmu3's.
 *
 * build_fmu.py compiles this file as binaries/x86_64-linux/<modelIdentifier>.so and moves
 * pythonfmu3's binary beside it as pythonfmu-export.so (fmu_build/win64.py: binaries/x86_64-windows/
 * <modelIdentifier>.dll with python_runtime_win.c, beside pythonfmu-export.dll). It adds what the FMI 2.0 layer
 * (fmi2_shim.c) adds for Python, and forwards every fmi3 function unchanged:
 *
 * 1. Python. Before pythonfmu3's binary is loaded, python_runtime_load() starts the Python the
 *    FMU carries (or the one named in resources/python_runtime.txt); a system below the FMU's
 *    glibc floor, or a Python that cannot start, is reported through the host's logMessage by
 *    fmi3Instantiate*, which returns NULL. pythonfmu3's binary is not linked to libpython:
 *    without this layer a C host fails with "undefined symbol: _Py_NoneStruct".
 *
 * 2. Exit. pythonfmu3's teardown writes into freed memory at process exit, as pythonfmu's
 *    does; python_runtime_open_binary() empties its interpreter holder first (release_binary
 *    in python_runtime.c).
 *
 * The instance pointer is pythonfmu3's own: no state of ours per instance.
 */
#include "shim_platform.h"  /* first: glibc_compat.h on Linux, windows.h on Windows */
#include "python_runtime.h"

#include <limits.h>
#include <stdio.h>
#include <string.h>

#define FMI3_Export SHIM_EXPORT
#include "fmi3/fmi3Functions.h"

#define INNER_BINARY SHIM_INNER_BINARY

/* The functions forwarded as they are: X(name, (parameters), (arguments)). */
#define FMI3_FORWARDED(X) \
    X(fmi3SetDebugLogging, (fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories, const fmi3String categories[]), (instance, loggingOn, nCategories, categories)) \
    X(fmi3EnterInitializationMode, (fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime), (instance, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime)) \
    X(fmi3ExitInitializationMode, (fmi3Instance instance), (instance)) \
    X(fmi3EnterEventMode, (fmi3Instance instance), (instance)) \
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
    X(fmi3GetClock, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Clock values[]), (instance, valueReferences, nValueReferences, values)) \
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
    X(fmi3SetClock, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Clock values[]), (instance, valueReferences, nValueReferences, values)) \
    X(fmi3GetNumberOfVariableDependencies, (fmi3Instance instance, fmi3ValueReference valueReference, size_t* nDependencies), (instance, valueReference, nDependencies)) \
    X(fmi3GetVariableDependencies, (fmi3Instance instance, fmi3ValueReference dependent, size_t elementIndicesOfDependent[], fmi3ValueReference independents[], size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[], size_t nDependencies), (instance, dependent, elementIndicesOfDependent, independents, elementIndicesOfIndependents, dependencyKinds, nDependencies)) \
    X(fmi3GetFMUState, (fmi3Instance instance, fmi3FMUState* FMUState), (instance, FMUState)) \
    X(fmi3SetFMUState, (fmi3Instance instance, fmi3FMUState FMUState), (instance, FMUState)) \
    X(fmi3FreeFMUState, (fmi3Instance instance, fmi3FMUState* FMUState), (instance, FMUState)) \
    X(fmi3SerializedFMUStateSize, (fmi3Instance instance, fmi3FMUState FMUState, size_t* size), (instance, FMUState, size)) \
    X(fmi3SerializeFMUState, (fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size), (instance, FMUState, serializedState, size)) \
    X(fmi3DeserializeFMUState, (fmi3Instance instance, const fmi3Byte serializedState[], size_t size, fmi3FMUState* FMUState), (instance, serializedState, size, FMUState)) \
    X(fmi3GetDirectionalDerivative, (fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity), (instance, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed, sensitivity, nSensitivity)) \
    X(fmi3GetAdjointDerivative, (fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity), (instance, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed, sensitivity, nSensitivity)) \
    X(fmi3EnterConfigurationMode, (fmi3Instance instance), (instance)) \
    X(fmi3ExitConfigurationMode, (fmi3Instance instance), (instance)) \
    X(fmi3GetIntervalDecimal, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]), (instance, valueReferences, nValueReferences, intervals, qualifiers)) \
    X(fmi3GetIntervalFraction, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]), (instance, valueReferences, nValueReferences, counters, resolutions, qualifiers)) \
    X(fmi3GetShiftDecimal, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 shifts[]), (instance, valueReferences, nValueReferences, shifts)) \
    X(fmi3GetShiftFraction, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]), (instance, valueReferences, nValueReferences, counters, resolutions)) \
    X(fmi3SetIntervalDecimal, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 intervals[]), (instance, valueReferences, nValueReferences, intervals)) \
    X(fmi3SetIntervalFraction, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]), (instance, valueReferences, nValueReferences, counters, resolutions)) \
    X(fmi3SetShiftDecimal, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 shifts[]), (instance, valueReferences, nValueReferences, shifts)) \
    X(fmi3SetShiftFraction, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]), (instance, valueReferences, nValueReferences, counters, resolutions)) \
    X(fmi3EvaluateDiscreteStates, (fmi3Instance instance), (instance)) \
    X(fmi3UpdateDiscreteStates, (fmi3Instance instance, fmi3Boolean* discreteStatesNeedUpdate, fmi3Boolean* terminateSimulation, fmi3Boolean* nominalsOfContinuousStatesChanged, fmi3Boolean* valuesOfContinuousStatesChanged, fmi3Boolean* nextEventTimeDefined, fmi3Float64* nextEventTime), (instance, discreteStatesNeedUpdate, terminateSimulation, nominalsOfContinuousStatesChanged, valuesOfContinuousStatesChanged, nextEventTimeDefined, nextEventTime)) \
    X(fmi3EnterContinuousTimeMode, (fmi3Instance instance), (instance)) \
    X(fmi3CompletedIntegratorStep, (fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* enterEventMode, fmi3Boolean* terminateSimulation), (instance, noSetFMUStatePriorToCurrentPoint, enterEventMode, terminateSimulation)) \
    X(fmi3SetTime, (fmi3Instance instance, fmi3Float64 time), (instance, time)) \
    X(fmi3SetContinuousStates, (fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates), (instance, continuousStates, nContinuousStates)) \
    X(fmi3GetContinuousStateDerivatives, (fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates), (instance, derivatives, nContinuousStates)) \
    X(fmi3GetEventIndicators, (fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators), (instance, eventIndicators, nEventIndicators)) \
    X(fmi3GetContinuousStates, (fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates), (instance, continuousStates, nContinuousStates)) \
    X(fmi3GetNominalsOfContinuousStates, (fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates), (instance, nominals, nContinuousStates)) \
    X(fmi3GetNumberOfEventIndicators, (fmi3Instance instance, size_t* nEventIndicators), (instance, nEventIndicators)) \
    X(fmi3GetNumberOfContinuousStates, (fmi3Instance instance, size_t* nContinuousStates), (instance, nContinuousStates)) \
    X(fmi3EnterStepMode, (fmi3Instance instance), (instance)) \
    X(fmi3GetOutputDerivatives, (fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues), (instance, valueReferences, nValueReferences, orders, values, nValues)) \
    X(fmi3DoStep, (fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime), (instance, currentCommunicationPoint, communicationStepSize, noSetFMUStatePriorToCurrentPoint, eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime)) \
    X(fmi3ActivateModelPartition, (fmi3Instance instance, fmi3ValueReference clockReference, fmi3Float64 activationTime), (instance, clockReference, activationTime))

#define MEMBER(name, params, args) fmi3Status(*name) params;
static struct {
    FMI3_FORWARDED(MEMBER)
    fmi3InstantiateModelExchangeTYPE *fmi3InstantiateModelExchange;
    fmi3InstantiateCoSimulationTYPE *fmi3InstantiateCoSimulation;
    fmi3InstantiateScheduledExecutionTYPE *fmi3InstantiateScheduledExecution;
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
            FMI3_FORWARDED(RESOLVE)
            RESOLVE_NAME(fmi3InstantiateModelExchange)
            RESOLVE_NAME(fmi3InstantiateCoSimulation)
            RESOLVE_NAME(fmi3InstantiateScheduledExecution)
            RESOLVE_NAME(fmi3FreeInstance)
        }
        inner_loaded = (status == 0);
    }
    pthread_mutex_unlock(&inner_lock);
    return status;
}

/* pythonfmu3's binary is released at exit (python_runtime.c): a call after that gets fmi3Error */
#define FORWARD(name, params, args)                              \
    FMI3_Export fmi3Status name params                           \
    {                                                            \
        if (!inner_loaded || !python_runtime_binary_open())      \
            return fmi3Error;                                    \
        return inner.name args;                                  \
    }
FMI3_FORWARDED(FORWARD)

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

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

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[], size_t nRequiredIntermediateVariables,
    fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3IntermediateUpdateCallback intermediateUpdate)
{
    char err[2048] = "";
    if (LOCATION_REFUSED(resourcePath) || load_inner(err, sizeof err) != 0) {
        report(instanceEnvironment, logMessage, err);
        return NULL;
    }
    return inner.fmi3InstantiateCoSimulation(instanceName, instantiationToken, resourcePath, visible, loggingOn,
                                             eventModeUsed, earlyReturnAllowed, requiredIntermediateVariables,
                                             nRequiredIntermediateVariables, instanceEnvironment, logMessage,
                                             intermediateUpdate);
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                                      fmi3String resourcePath, fmi3Boolean visible,
                                                      fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                                      fmi3LogMessageCallback logMessage)
{
    char err[2048] = "";
    if (LOCATION_REFUSED(resourcePath) || load_inner(err, sizeof err) != 0) {
        report(instanceEnvironment, logMessage, err);
        return NULL;
    }
    return inner.fmi3InstantiateModelExchange(instanceName, instantiationToken, resourcePath, visible, loggingOn,
                                              instanceEnvironment, logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption)
{
    char err[2048] = "";
    if (LOCATION_REFUSED(resourcePath) || load_inner(err, sizeof err) != 0) {
        report(instanceEnvironment, logMessage, err);
        return NULL;
    }
    return inner.fmi3InstantiateScheduledExecution(instanceName, instantiationToken, resourcePath, visible, loggingOn,
                                                   instanceEnvironment, logMessage, clockUpdate, lockPreemption,
                                                   unlockPreemption);
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance)
{
    if (instance && inner_loaded && python_runtime_binary_open())
        inner.fmi3FreeInstance(instance);
}
