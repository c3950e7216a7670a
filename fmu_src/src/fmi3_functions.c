/* The FMI 3.0 entry points, co-simulation and model exchange: state machine, argument checks,
   then one call into instance.c, as fmi2_functions.c does for FMI 2.0. Which states each function
   is allowed in is data: one mask per function (FMI 3.0, sections 3.2 and 4.2; the core's
   STEP_COMPLETE is step mode, STEP_FAILED step discarded). Everything FMI 3.0 offers that a
   model without events and with Float64 variables only (HAS_EVENTS 0, FLOAT64_ONLY 1 in its
   config.h) has no use for (clocks, scheduled execution, configuration mode, event mode in
   co-simulation, variables other than Float64) answers fmi3Error with a line saying why. */

#include <stddef.h>

#include "fmi3Functions.h"
#include "instance.h"

/* The independent variable `time` has the value reference after the model's variables: the
   FMI 3.0 model description (fmu_build/fmi3.py) numbers it so. */
#define VR_TIME N_VALUE_REFERENCES

#define ANY_STATE (CO_SIMULATION_STATES | MODEL_EXCHANGE_STATES)
#define RUNNING (STATE_STEP_COMPLETE | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)
#define ANY_INITIALIZED (RUNNING | STATE_STEP_FAILED | STATE_TERMINATED)

#define MASK_fmi3SetDebugLogging                 ANY_STATE
#define MASK_fmi3EnterInitializationMode         STATE_INSTANTIATED
#define MASK_fmi3ExitInitializationMode          STATE_INITIALIZATION_MODE
#define MASK_fmi3EnterEventMode                  STATE_CONTINUOUS_TIME_MODE
#define MASK_fmi3Terminate                       (RUNNING | STATE_STEP_FAILED)
#define MASK_fmi3Reset                           ANY_STATE
#define MASK_fmi3GetFloat64                      ANY_STATE
#define MASK_fmi3SetFloat64                      (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE | RUNNING)
#define MASK_fmi3GetFloat32                      MASK_fmi3GetFloat64
#define MASK_fmi3GetInt8                         MASK_fmi3GetFloat64
#define MASK_fmi3GetUInt8                        MASK_fmi3GetFloat64
#define MASK_fmi3GetInt16                        MASK_fmi3GetFloat64
#define MASK_fmi3GetUInt16                       MASK_fmi3GetFloat64
#define MASK_fmi3GetInt32                        MASK_fmi3GetFloat64
#define MASK_fmi3GetUInt32                       MASK_fmi3GetFloat64
#define MASK_fmi3GetInt64                        MASK_fmi3GetFloat64
#define MASK_fmi3GetUInt64                       MASK_fmi3GetFloat64
#define MASK_fmi3GetBoolean                      MASK_fmi3GetFloat64
#define MASK_fmi3GetString                       MASK_fmi3GetFloat64
#define MASK_fmi3GetBinary                       MASK_fmi3GetFloat64
#define MASK_fmi3SetFloat32                      MASK_fmi3SetFloat64
#define MASK_fmi3SetInt8                         MASK_fmi3SetFloat64
#define MASK_fmi3SetUInt8                        MASK_fmi3SetFloat64
#define MASK_fmi3SetInt16                        MASK_fmi3SetFloat64
#define MASK_fmi3SetUInt16                       MASK_fmi3SetFloat64
#define MASK_fmi3SetInt32                        MASK_fmi3SetFloat64
#define MASK_fmi3SetUInt32                       MASK_fmi3SetFloat64
#define MASK_fmi3SetInt64                        MASK_fmi3SetFloat64
#define MASK_fmi3SetUInt64                       MASK_fmi3SetFloat64
#define MASK_fmi3SetBoolean                      MASK_fmi3SetFloat64
#define MASK_fmi3SetString                       MASK_fmi3SetFloat64
#define MASK_fmi3SetBinary                       MASK_fmi3SetFloat64
#define MASK_fmi3GetFMUState                     ANY_STATE
#define MASK_fmi3SetFMUState                     ANY_STATE
#define MASK_fmi3FreeFMUState                    ANY_STATE
#define MASK_fmi3SerializedFMUStateSize          ANY_STATE
#define MASK_fmi3SerializeFMUState               ANY_STATE
#define MASK_fmi3DeserializeFMUState             ANY_STATE
#define MASK_fmi3GetDirectionalDerivative        (STATE_INITIALIZATION_MODE | ANY_INITIALIZED)
#define MASK_fmi3GetAdjointDerivative            MASK_fmi3GetDirectionalDerivative
#define MASK_fmi3EvaluateDiscreteStates          RUNNING
#define MASK_fmi3UpdateDiscreteStates            STATE_EVENT_MODE
#define MASK_fmi3EnterContinuousTimeMode         (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE)
#define MASK_fmi3CompletedIntegratorStep         (MODEL_EXCHANGE_ONLY | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi3SetTime                         (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi3SetContinuousStates             (MODEL_EXCHANGE_ONLY | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi3GetContinuousStateDerivatives   (MODEL_EXCHANGE_ONLY | STATE_INITIALIZATION_MODE | STATE_EVENT_MODE \
                                                  | STATE_CONTINUOUS_TIME_MODE | STATE_TERMINATED)
#define MASK_fmi3GetEventIndicators              MASK_fmi3GetContinuousStateDerivatives
#define MASK_fmi3GetContinuousStates             MASK_fmi3GetContinuousStateDerivatives
#define MASK_fmi3GetNominalsOfContinuousStates   MASK_fmi3GetContinuousStateDerivatives
#define MASK_fmi3GetNumberOfEventIndicators      ANY_STATE
#define MASK_fmi3GetNumberOfContinuousStates     ANY_STATE
#define MASK_fmi3GetOutputDerivatives            (CO_SIMULATION_ONLY | STATE_STEP_COMPLETE | STATE_STEP_FAILED \
                                                  | STATE_TERMINATED)
#define MASK_fmi3DoStep                          (CO_SIMULATION_ONLY | STATE_STEP_COMPLETE)
/* Not supported in any state: they answer why after the NULL check. */
#define MASK_fmi3GetClock                        ANY_STATE
#define MASK_fmi3SetClock                        ANY_STATE
#define MASK_fmi3GetNumberOfVariableDependencies ANY_STATE
#define MASK_fmi3GetVariableDependencies         ANY_STATE
#define MASK_fmi3EnterConfigurationMode          ANY_STATE
#define MASK_fmi3ExitConfigurationMode           ANY_STATE
#define MASK_fmi3GetIntervalDecimal              ANY_STATE
#define MASK_fmi3GetIntervalFraction             ANY_STATE
#define MASK_fmi3GetShiftDecimal                 ANY_STATE
#define MASK_fmi3GetShiftFraction                ANY_STATE
#define MASK_fmi3SetIntervalDecimal              ANY_STATE
#define MASK_fmi3SetIntervalFraction             ANY_STATE
#define MASK_fmi3SetShiftDecimal                 ANY_STATE
#define MASK_fmi3SetShiftFraction                ANY_STATE
#define MASK_fmi3EnterStepMode                   ANY_STATE
#define MASK_fmi3ActivateModelPartition          ANY_STATE

/* Every function with an instance starts here: NULL instance, then the state mask. */
#define ENTER(name)                                                                    \
    static const char function[] = #name;                                             \
    Instance *instance = (Instance *)c;                                                \
    if (!instance || !instance_state_allows(instance, MASK_##name, function))          \
        return fmi3Error;

/* Array arguments may be NULL only when their length is 0. */
#define REQUIRE_ARRAY(name, length)                                                    \
    if ((length) > 0 && instance_null_argument(instance, function, #name, name))       \
        return fmi3Error;

/* Every variable is a scalar, so each array of values has one entry per value reference. */
#define REQUIRE_COUNT(count, expected)                                                 \
    if ((count) != (expected))                                                         \
        return STATUS(instance_error(instance, function, "%s = %lu, expected %lu (every " \
                                     "variable is a scalar)", #count, (unsigned long)(count), \
                                     (unsigned long)(expected)));

/* fmi3Status has the core's values. */
#define STATUS(call) ((fmi3Status)(call))

/* Fails to compile unless the cast in STATUS keeps every status's meaning. */
typedef char status_values_match[(STATUS_OK == (int)fmi3OK && STATUS_WARNING == (int)fmi3Warning
                                  && STATUS_DISCARD == (int)fmi3Discard && STATUS_ERROR == (int)fmi3Error
                                  && STATUS_FATAL == (int)fmi3Fatal) ? 1 : -1];

#define NOT_SUPPORTED(why) return STATUS(instance_error(instance, function, "not supported: %s", why))

static const char NO_CLOCKS[] = "the model has no clocks";

static void forward_to_fmi3_logger(AnyFunction master_logger, void *environment,
                                   const char *instance_name, Status status, const char *category,
                                   const char *message) {
    (void)instance_name; /* FMI 3.0's logger has no instance name: the environment says whose */
    ((fmi3LogMessageCallback)master_logger)(environment, (fmi3Status)status, category, message);
}

/* The functions a master calls every step go through these only when the record is on
   (WITHOUT_RECORD, instance.h). */
static NOINLINE fmi3Status recorded_get_float64(Instance *instance, const char *function,
                                                const fmi3ValueReference vr[], size_t nvr,
                                                fmi3Float64 values[], size_t n_values) {
    WITHOUT_RECORD(fmi3Status, fmi3GetFloat64(instance, vr, nvr, values, n_values))
    RECORD_VALUES((Status)status, vr, NULL, status == fmi3OK ? nvr : 0, values)
    return status;
}

static NOINLINE fmi3Status recorded_set_float64(Instance *instance, const char *function,
                                                const fmi3ValueReference vr[], size_t nvr,
                                                const fmi3Float64 values[], size_t n_values) {
    WITHOUT_RECORD(fmi3Status, fmi3SetFloat64(instance, vr, nvr, values, n_values))
    RECORD_VALUES((Status)status, vr, NULL, nvr == n_values ? nvr : 0, values)
    return status;
}

static NOINLINE fmi3Status recorded_do_step(Instance *instance, const char *function,
                                            fmi3Float64 communication_point,
                                            fmi3Float64 communication_step,
                                            fmi3Boolean no_set_state_prior,
                                            fmi3Boolean *event_handling_needed,
                                            fmi3Boolean *terminate_simulation,
                                            fmi3Boolean *early_return,
                                            fmi3Float64 *last_successful_time) {
    WITHOUT_RECORD(fmi3Status, fmi3DoStep(instance, communication_point, communication_step,
                                          no_set_state_prior, event_handling_needed,
                                          terminate_simulation, early_return, last_successful_time))
    RECORD((Status)status, "currentCommunicationPoint=%.17g, communicationStepSize=%.17g",
           communication_point, communication_step)
    return status;
}

static fmi3Instance instantiate(const char *function, fmi3String name, fmi3String token,
                                InterfaceType type, fmi3Boolean loggingOn,
                                fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback logMessage) {
    const Logger logger = {forward_to_fmi3_logger, (AnyFunction)logMessage, environment};
    return instance_create(function, name, "instantiationToken", token, type, &logger, loggingOn);
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    ENTER(fmi3SetDebugLogging)
    return STATUS(instance_set_debug_logging(instance, function, loggingOn, nCategories, categories));
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath; /* the model needs no resources */
    (void)visible;
    return instantiate("fmi3InstantiateModelExchange", instanceName, instantiationToken,
                       INTERFACE_MODEL_EXCHANGE, loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible,
                                         fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
                                         fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath, (void)visible;
    /* The FMU declares hasEventMode="false" and never returns early or asks for intermediate
       updates, so what the master offers for those goes unused. */
    (void)eventModeUsed, (void)earlyReturnAllowed, (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables, (void)intermediateUpdate;
    return instantiate("fmi3InstantiateCoSimulation", instanceName, instantiationToken,
                       INTERFACE_CO_SIMULATION, loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible,
                                               fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    (void)clockUpdate, (void)lockPreemption, (void)unlockPreemption;
    const Logger logger = {forward_to_fmi3_logger, (AnyFunction)logMessage, instanceEnvironment};
    return instance_refuse("fmi3InstantiateScheduledExecution", instanceName, &logger,
                           "not supported: the model has no clocks to schedule (the model "
                           "description has no <ScheduledExecution>)");
}

void fmi3FreeInstance(fmi3Instance c) {
    static const char function[] = "fmi3FreeInstance";
    Instance *instance = (Instance *)c;
    if (instance) {
        KEEP_TIME
        RECORD(STATUS_OK, "")
    }
    instance_free(instance);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    /* stopTime is only recorded: a model without events has no end of its own. */
    ENTER(fmi3EnterInitializationMode)
    KEEP_TIME
    const Status status = instance_setup_experiment(instance, function, toleranceDefined, tolerance,
                                                    startTime);
    if (status == STATUS_OK) instance->data.machine_state = STATE_INITIALIZATION_MODE;
    RECORD(status, "toleranceDefined=%d, tolerance=%.17g, startTime=%.17g, stopTimeDefined=%d, "
           "stopTime=%.17g", (int)toleranceDefined, tolerance, startTime, (int)stopTimeDefined, stopTime)
    return STATUS(status);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c) {
    ENTER(fmi3ExitInitializationMode)
    KEEP_TIME
    const Status status = instance_exit_initialization(instance, function);
    RECORD(status, "")
    return STATUS(status);
}

fmi3Status fmi3EnterEventMode(fmi3Instance c) {
    ENTER(fmi3EnterEventMode)
    KEEP_TIME
    instance->data.machine_state = STATE_EVENT_MODE;
    RECORD(STATUS_OK, "")
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance c) {
    ENTER(fmi3Terminate)
    KEEP_TIME
    instance->data.machine_state = STATE_TERMINATED;
    RECORD(STATUS_OK, "")
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance c) {
    ENTER(fmi3Reset)
    KEEP_TIME
    instance_reset(instance);
    RECORD(STATUS_OK, "")
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    ENTER(fmi3GetFloat64)
    if (instance_recording(instance))
        return recorded_get_float64(instance, function, valueReferences, nValueReferences, values,
                                    nValues);
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    REQUIRE_ARRAY(values, nValues)
    REQUIRE_COUNT(nValues, nValueReferences)
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] == VR_TIME) {
            values[i] = instance->data.time;
            continue;
        }
        const Status status = instance_get_real(instance, function, &valueReferences[i], 1, &values[i]);
        if (status != STATUS_OK) return STATUS(status);
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER(fmi3SetFloat64)
    if (instance_recording(instance))
        return recorded_set_float64(instance, function, valueReferences, nValueReferences, values,
                                    nValues);
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    REQUIRE_ARRAY(values, nValues)
    REQUIRE_COUNT(nValues, nValueReferences)
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] == VR_TIME)
            return STATUS(instance_error(instance, function, "cannot set time: it is the "
                                         "independent variable (fmi3SetTime and fmi3DoStep advance it)"));
    }
    return STATUS(instance_set_real(instance, function, valueReferences, nValueReferences, values));
}

/* The model has Float64 variables (FLOAT64_ONLY 1 in its config.h) and String parameters only:
   any reference of another type is unknown. */
#if !FLOAT64_ONLY
#error "FLOAT64_ONLY 0: the FMI plumbing has getters and setters for Float64 variables only"
#endif
#define NO_VARIABLES_OF_TYPE(name, values_type)                                                \
    fmi3Status name(fmi3Instance c, const fmi3ValueReference valueReferences[],                 \
                    size_t nValueReferences, values_type values, size_t nValues) {              \
        (void)values, (void)nValues;                                                            \
        ENTER(name)                                                                             \
        REQUIRE_ARRAY(valueReferences, nValueReferences)                                        \
        if (nValueReferences == 0) return fmi3OK;                                               \
        return STATUS(instance_error(instance, function,                                        \
                                     "vr %u: this FMU has no variables of this type (all are " \
                                     "Float64)", valueReferences[0]));                          \
    }

NO_VARIABLES_OF_TYPE(fmi3GetFloat32, fmi3Float32 *)
NO_VARIABLES_OF_TYPE(fmi3GetInt8, fmi3Int8 *)
NO_VARIABLES_OF_TYPE(fmi3GetUInt8, fmi3UInt8 *)
NO_VARIABLES_OF_TYPE(fmi3GetInt16, fmi3Int16 *)
NO_VARIABLES_OF_TYPE(fmi3GetUInt16, fmi3UInt16 *)
NO_VARIABLES_OF_TYPE(fmi3GetInt32, fmi3Int32 *)
NO_VARIABLES_OF_TYPE(fmi3GetUInt32, fmi3UInt32 *)
NO_VARIABLES_OF_TYPE(fmi3GetInt64, fmi3Int64 *)
NO_VARIABLES_OF_TYPE(fmi3GetUInt64, fmi3UInt64 *)
NO_VARIABLES_OF_TYPE(fmi3GetBoolean, fmi3Boolean *)

fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3String values[], size_t nValues) {
    ENTER(fmi3GetString)
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    REQUIRE_ARRAY(values, nValues)
    REQUIRE_COUNT(nValues, nValueReferences)
    return STATUS(instance_get_string(instance, function, valueReferences, nValueReferences, values));
}
NO_VARIABLES_OF_TYPE(fmi3SetFloat32, const fmi3Float32 *)
NO_VARIABLES_OF_TYPE(fmi3SetInt8, const fmi3Int8 *)
NO_VARIABLES_OF_TYPE(fmi3SetUInt8, const fmi3UInt8 *)
NO_VARIABLES_OF_TYPE(fmi3SetInt16, const fmi3Int16 *)
NO_VARIABLES_OF_TYPE(fmi3SetUInt16, const fmi3UInt16 *)
NO_VARIABLES_OF_TYPE(fmi3SetInt32, const fmi3Int32 *)
NO_VARIABLES_OF_TYPE(fmi3SetUInt32, const fmi3UInt32 *)
NO_VARIABLES_OF_TYPE(fmi3SetInt64, const fmi3Int64 *)
NO_VARIABLES_OF_TYPE(fmi3SetUInt64, const fmi3UInt64 *)
NO_VARIABLES_OF_TYPE(fmi3SetBoolean, const fmi3Boolean *)

fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3String values[], size_t nValues) {
    ENTER(fmi3SetString)
    KEEP_TIME
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    REQUIRE_ARRAY(values, nValues)
    REQUIRE_COUNT(nValues, nValueReferences)
    const Status status = instance_set_string(instance, function, valueReferences, nValueReferences, values);
    char file[ESCAPED_SIZE(MAX_RECORD_FILE_NAME)];
    RECORD(status, "file=\"%s\"", escape_text(file, sizeof(file), instance->record_file_name))
    return STATUS(status);
}

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[],
                         size_t nValues) {
    (void)valueSizes, (void)values, (void)nValues;
    ENTER(fmi3GetBinary)
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    if (nValueReferences == 0) return fmi3OK;
    return STATUS(instance_error(instance, function, "vr %u: this FMU has no variables of this "
                                 "type (all are Float64)", valueReferences[0]));
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[],
                         size_t nValues) {
    (void)valueSizes, (void)values, (void)nValues;
    ENTER(fmi3SetBinary)
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    if (nValueReferences == 0) return fmi3OK;
    return STATUS(instance_error(instance, function, "vr %u: this FMU has no variables of this "
                                 "type (all are Float64)", valueReferences[0]));
}

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[]) {
    (void)valueReferences, (void)nValueReferences, (void)values;
    ENTER(fmi3GetClock)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[]) {
    (void)valueReferences, (void)nValueReferences, (void)values;
    ENTER(fmi3SetClock)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference, (void)nDependencies;
    ENTER(fmi3GetNumberOfVariableDependencies)
    NOT_SUPPORTED("the dependencies are in the model description's <ModelStructure> "
                  "(providesPerElementDependencies is false)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[], size_t nDependencies) {
    (void)dependent, (void)elementIndicesOfDependent, (void)independents;
    (void)elementIndicesOfIndependents, (void)dependencyKinds, (void)nDependencies;
    ENTER(fmi3GetVariableDependencies)
    NOT_SUPPORTED("the dependencies are in the model description's <ModelStructure> "
                  "(providesPerElementDependencies is false)");
}

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *FMUState) {
    ENTER(fmi3GetFMUState)
    KEEP_TIME
    const Status status = instance_get_state(instance, function, FMUState);
    RECORD(status, "state=%p", (void *)(FMUState ? *FMUState : NULL))
    return STATUS(status);
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState FMUState) {
    ENTER(fmi3SetFMUState)
    KEEP_TIME
    const Status status = instance_set_state(instance, function, FMUState);
    RECORD(status, "state=%p", (void *)(FMUState))
    return STATUS(status);
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *FMUState) {
    ENTER(fmi3FreeFMUState)
    KEEP_TIME
    void *const freed = FMUState ? *FMUState : NULL;
    const Status status = instance_free_state(instance, function, FMUState);
    RECORD(status, "state=%p", freed)
    return STATUS(status);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState FMUState, size_t *size) {
    ENTER(fmi3SerializedFMUStateSize)
    KEEP_TIME
    const Status status = instance_serialized_state_size(instance, function, FMUState, size);
    RECORD(status, "state=%p", (void *)(FMUState))
    return STATUS(status);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size) {
    ENTER(fmi3SerializeFMUState)
    KEEP_TIME
    const Status status = instance_serialize_state(instance, function, FMUState, serializedState, size);
    RECORD(status, "state=%p", (void *)(FMUState))
    return STATUS(status);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    ENTER(fmi3DeserializeFMUState)
    KEEP_TIME
    const Status status = instance_deserialize_state(instance, function, serializedState, size, FMUState);
    RECORD(status, "state=%p", (void *)(FMUState ? *FMUState : NULL))
    return STATUS(status);
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[],
                                        size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    ENTER(fmi3GetDirectionalDerivative)
    REQUIRE_ARRAY(unknowns, nUnknowns)
    REQUIRE_ARRAY(knowns, nKnowns)
    REQUIRE_ARRAY(seed, nSeed)
    REQUIRE_ARRAY(sensitivity, nSensitivity)
    REQUIRE_COUNT(nSeed, nKnowns)
    REQUIRE_COUNT(nSensitivity, nUnknowns)
    return STATUS(instance_directional_derivative(instance, function, unknowns, nUnknowns, knowns,
                                                  nKnowns, seed, sensitivity));
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    ENTER(fmi3GetAdjointDerivative)
    REQUIRE_ARRAY(unknowns, nUnknowns)
    REQUIRE_ARRAY(knowns, nKnowns)
    REQUIRE_ARRAY(seed, nSeed)
    REQUIRE_ARRAY(sensitivity, nSensitivity)
    REQUIRE_COUNT(nSeed, nUnknowns)
    REQUIRE_COUNT(nSensitivity, nKnowns)
    return STATUS(instance_adjoint_derivative(instance, function, unknowns, nUnknowns, knowns,
                                              nKnowns, seed, sensitivity));
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
    ENTER(fmi3EnterConfigurationMode)
    NOT_SUPPORTED("the model has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
    ENTER(fmi3ExitConfigurationMode)
    NOT_SUPPORTED("the model has no structural parameters");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences, (void)nValueReferences, (void)intervals, (void)qualifiers;
    ENTER(fmi3GetIntervalDecimal)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions, (void)qualifiers;
    ENTER(fmi3GetIntervalFraction)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    ENTER(fmi3GetShiftDecimal)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[]) {
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    ENTER(fmi3GetShiftFraction)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[]) {
    (void)valueReferences, (void)nValueReferences, (void)intervals;
    ENTER(fmi3SetIntervalDecimal)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    ENTER(fmi3SetIntervalFraction)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[]) {
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    ENTER(fmi3SetShiftDecimal)
    NOT_SUPPORTED(NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[]) {
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    ENTER(fmi3SetShiftFraction)
    NOT_SUPPORTED(NO_CLOCKS);
}

/* A model without events (HAS_EVENTS 0 in its config.h) has no discrete states: event mode only
   passes through. */
#if HAS_EVENTS
#error "HAS_EVENTS 1: the FMI plumbing has no event indicators or discrete states yet"
#endif

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) {
    ENTER(fmi3EvaluateDiscreteStates)
    return fmi3OK;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime) {
    ENTER(fmi3UpdateDiscreteStates)
    fmi3Boolean *flags[] = {discreteStatesNeedUpdate, terminateSimulation,
                            nominalsOfContinuousStatesChanged, valuesOfContinuousStatesChanged,
                            nextEventTimeDefined};
    static const char *const names[] = {"discreteStatesNeedUpdate", "terminateSimulation",
                                        "nominalsOfContinuousStatesChanged",
                                        "valuesOfContinuousStatesChanged", "nextEventTimeDefined"};
    for (size_t i = 0; i < sizeof(flags) / sizeof(flags[0]); i++) {
        if (instance_null_argument(instance, function, names[i], flags[i])) return fmi3Error;
    }
    if (instance_null_argument(instance, function, "nextEventTime", nextEventTime)) return fmi3Error;
    for (size_t i = 0; i < sizeof(flags) / sizeof(flags[0]); i++) *flags[i] = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) {
    ENTER(fmi3EnterContinuousTimeMode)
    KEEP_TIME
    instance->data.machine_state = STATE_CONTINUOUS_TIME_MODE;
    RECORD(STATUS_OK, "")
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(fmi3CompletedIntegratorStep)
    if (instance_null_argument(instance, function, "enterEventMode", enterEventMode) ||
        instance_null_argument(instance, function, "terminateSimulation", terminateSimulation))
        return fmi3Error;
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    KEEP_TIME
    RECORD(STATUS_OK, "")
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time) {
    ENTER(fmi3SetTime)
    KEEP_TIME
    const Status status = instance_set_time(instance, function, time);
    RECORD(status, "time=%.17g", time)
    return STATUS(status);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    ENTER(fmi3SetContinuousStates)
    KEEP_TIME
    REQUIRE_ARRAY(continuousStates, nContinuousStates)
    const Status status = instance_set_states(instance, function, continuousStates, nContinuousStates);
    RECORD_VALUES(status, NULL, NULL, status == STATUS_OK ? nContinuousStates : 0, continuousStates)
    return STATUS(status);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    ENTER(fmi3GetContinuousStateDerivatives)
    KEEP_TIME
    REQUIRE_ARRAY(derivatives, nContinuousStates)
    const Status status = instance_get_derivatives(instance, function, derivatives, nContinuousStates);
    RECORD_VALUES(status, NULL, NULL, status == STATUS_OK ? nContinuousStates : 0, derivatives)
    return STATUS(status);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[],
                                  size_t nEventIndicators) {
    (void)eventIndicators;
    ENTER(fmi3GetEventIndicators)
    if (nEventIndicators == 0) return fmi3OK;
    return STATUS(instance_error(instance, function, "nEventIndicators = %lu, but the model has "
                                 "no event indicators", (unsigned long)nEventIndicators));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    ENTER(fmi3GetContinuousStates)
    REQUIRE_ARRAY(continuousStates, nContinuousStates)
    return STATUS(instance_get_states(instance, function, continuousStates, nContinuousStates));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[],
                                             size_t nContinuousStates) {
    ENTER(fmi3GetNominalsOfContinuousStates)
    REQUIRE_ARRAY(nominals, nContinuousStates)
    return STATUS(instance_get_nominals(instance, function, nominals, nContinuousStates));
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators) {
    ENTER(fmi3GetNumberOfEventIndicators)
    if (instance_null_argument(instance, function, "nEventIndicators", nEventIndicators))
        return fmi3Error;
    *nEventIndicators = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates) {
    ENTER(fmi3GetNumberOfContinuousStates)
    if (instance_null_argument(instance, function, "nContinuousStates", nContinuousStates))
        return fmi3Error;
    *nContinuousStates = N_STATES;
    return fmi3OK;
}

fmi3Status fmi3EnterStepMode(fmi3Instance c) {
    ENTER(fmi3EnterStepMode)
    NOT_SUPPORTED("co-simulation has no event mode here (hasEventMode is false): "
                  "fmi3ExitInitializationMode enters step mode directly");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[],
                                    fmi3Float64 values[], size_t nValues) {
    ENTER(fmi3GetOutputDerivatives)
    REQUIRE_ARRAY(valueReferences, nValueReferences)
    REQUIRE_ARRAY(orders, nValueReferences)
    REQUIRE_ARRAY(values, nValues)
    REQUIRE_COUNT(nValues, nValueReferences)
    return STATUS(instance_get_output_derivatives(instance, function, valueReferences,
                                                  nValueReferences, orders, values));
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    /* noSetFMUStatePriorToCurrentPoint only passes through: states are copies, nothing to release
       early. */
    ENTER(fmi3DoStep)
    if (instance_recording(instance))
        return recorded_do_step(instance, function, currentCommunicationPoint, communicationStepSize,
                                noSetFMUStatePriorToCurrentPoint, eventHandlingNeeded,
                                terminateSimulation, earlyReturn, lastSuccessfulTime);
    if (instance_null_argument(instance, function, "eventHandlingNeeded", eventHandlingNeeded) ||
        instance_null_argument(instance, function, "terminateSimulation", terminateSimulation) ||
        instance_null_argument(instance, function, "earlyReturn", earlyReturn) ||
        instance_null_argument(instance, function, "lastSuccessfulTime", lastSuccessfulTime))
        return fmi3Error;
    const Status status = instance_do_step(instance, function, currentCommunicationPoint,
                                           communicationStepSize);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = instance->data.last_successful_time;
    return STATUS(status);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference, (void)activationTime;
    ENTER(fmi3ActivateModelPartition)
    NOT_SUPPORTED("the model has no clocks to schedule (no <ScheduledExecution>)");
}
