/* The FMI 2.0 entry points, co-simulation and model exchange: state machine, argument checks,
   then one call into instance.c. Which states each function is allowed in is data: one mask
   per function (FMI 2.0, tables in sections 3.2.3 and 4.2.4). */

#include <stddef.h>

#include "fmi2Functions.h"
#include "instance.h"

#define ANY_INITIALIZED (STATE_STEP_COMPLETE | STATE_STEP_FAILED | STATE_TERMINATED \
                         | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)
#define ANY_STATE (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE | ANY_INITIALIZED)
#define RUNNING (STATE_STEP_COMPLETE | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)

#define MASK_fmi2SetDebugLogging              ANY_STATE
#define MASK_fmi2SetupExperiment              STATE_INSTANTIATED
#define MASK_fmi2EnterInitializationMode      STATE_INSTANTIATED
#define MASK_fmi2ExitInitializationMode       STATE_INITIALIZATION_MODE
#define MASK_fmi2Terminate                    (RUNNING | STATE_STEP_FAILED)
#define MASK_fmi2Reset                        ANY_STATE
#define MASK_fmi2GetReal                      (STATE_INITIALIZATION_MODE | ANY_INITIALIZED)
#define MASK_fmi2GetInteger                   MASK_fmi2GetReal
#define MASK_fmi2GetBoolean                   MASK_fmi2GetReal
#define MASK_fmi2GetString                    MASK_fmi2GetReal
#define MASK_fmi2SetReal                      (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE \
                                               | RUNNING)
#define MASK_fmi2SetInteger                   MASK_fmi2SetReal
#define MASK_fmi2SetBoolean                   MASK_fmi2SetReal
#define MASK_fmi2SetString                    MASK_fmi2SetReal
#define MASK_fmi2GetFMUstate                  ANY_STATE
#define MASK_fmi2SetFMUstate                  ANY_STATE
#define MASK_fmi2FreeFMUstate                 ANY_STATE
#define MASK_fmi2SerializedFMUstateSize       ANY_STATE
#define MASK_fmi2SerializeFMUstate            ANY_STATE
#define MASK_fmi2DeSerializeFMUstate          ANY_STATE
#define MASK_fmi2GetDirectionalDerivative     (STATE_INITIALIZATION_MODE | ANY_INITIALIZED)
#define MASK_fmi2SetRealInputDerivatives      (CO_SIMULATION_ONLY | STATE_INSTANTIATED | STATE_INITIALIZATION_MODE \
                                               | STATE_STEP_COMPLETE)
#define MASK_fmi2GetRealOutputDerivatives     (CO_SIMULATION_ONLY | STATE_STEP_COMPLETE | STATE_STEP_FAILED \
                                               | STATE_TERMINATED)
#define MASK_fmi2DoStep                       (CO_SIMULATION_ONLY | STATE_STEP_COMPLETE)
#define MASK_fmi2CancelStep                   CO_SIMULATION_ONLY
#define MASK_fmi2GetStatus                    (CO_SIMULATION_ONLY | STATE_STEP_COMPLETE | STATE_STEP_FAILED \
                                               | STATE_TERMINATED)
#define MASK_fmi2GetRealStatus                MASK_fmi2GetStatus
#define MASK_fmi2GetIntegerStatus             MASK_fmi2GetStatus
#define MASK_fmi2GetBooleanStatus             MASK_fmi2GetStatus
#define MASK_fmi2GetStringStatus              MASK_fmi2GetStatus
#define MASK_fmi2EnterEventMode               (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi2NewDiscreteStates            (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE)
#define MASK_fmi2EnterContinuousTimeMode      (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE)
#define MASK_fmi2CompletedIntegratorStep      (MODEL_EXCHANGE_ONLY | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi2SetTime                      (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi2SetContinuousStates          (MODEL_EXCHANGE_ONLY | STATE_CONTINUOUS_TIME_MODE)
#define MASK_fmi2GetEventIndicators           (MODEL_EXCHANGE_ONLY | STATE_INITIALIZATION_MODE | STATE_EVENT_MODE \
                                               | STATE_CONTINUOUS_TIME_MODE | STATE_TERMINATED)
#define MASK_fmi2GetContinuousStates          MASK_fmi2GetEventIndicators
#define MASK_fmi2GetDerivatives               (MODEL_EXCHANGE_ONLY | STATE_EVENT_MODE | STATE_CONTINUOUS_TIME_MODE \
                                               | STATE_TERMINATED)
#define MASK_fmi2GetNominalsOfContinuousStates (MODEL_EXCHANGE_ONLY | STATE_INSTANTIATED | STATE_EVENT_MODE \
                                               | STATE_CONTINUOUS_TIME_MODE | STATE_TERMINATED)

/* Every function with an instance starts here: NULL instance, then the state mask. Each
   function's name travels into the core for its messages (a refused call is recorded there). */
#define ENTER(name)                                                                    \
    static const char function[] = #name;                                             \
    Instance *instance = (Instance *)c;                                                \
    if (!instance || !instance_state_allows(instance, MASK_##name, function))          \
        return fmi2Error;




/* Array arguments may be NULL only when their length is 0. */
#define REQUIRE_ARRAY(name, length)                                                    \
    if ((length) > 0 && instance_null_argument(instance, function, #name, name))       \
        return fmi2Error;

/* fmi2Status has the core's values (and one more, fmi2Pending, which the core never returns). */
#define STATUS(call) ((fmi2Status)(call))

/* Fails to compile unless the cast in STATUS keeps every status's meaning. */
typedef char status_values_match[(STATUS_OK == (int)fmi2OK && STATUS_WARNING == (int)fmi2Warning
                                  && STATUS_DISCARD == (int)fmi2Discard && STATUS_ERROR == (int)fmi2Error
                                  && STATUS_FATAL == (int)fmi2Fatal) ? 1 : -1];

static void forward_to_fmi2_logger(AnyFunction master_logger, void *environment,
                                   const char *instance_name, Status status, const char *category,
                                   const char *message) {
    ((fmi2CallbackLogger)master_logger)(environment, instance_name, (fmi2Status)status, category,
                                        message);
}


/* The functions a master calls every step go through these only when the record is on
   (WITHOUT_RECORD, instance.h). */
static NOINLINE fmi2Status recorded_get_real(Instance *instance, const char *function,
                                             const unsigned int vr[], size_t nvr, double value[]) {
    WITHOUT_RECORD(fmi2Status, fmi2GetReal(instance, vr, nvr, value))
    RECORD_VALUES((Status)status, vr, NULL, status == fmi2OK ? nvr : 0, value)
    return status;
}

static NOINLINE fmi2Status recorded_set_real(Instance *instance, const char *function,
                                             const unsigned int vr[], size_t nvr,
                                             const double value[]) {
    WITHOUT_RECORD(fmi2Status, fmi2SetReal(instance, vr, nvr, value))
    RECORD_VALUES((Status)status, vr, NULL, nvr, value)
    return status;
}

static NOINLINE fmi2Status recorded_input_derivatives(Instance *instance, const char *function,
                                                      const unsigned int vr[], size_t nvr,
                                                      const int order[], const double value[]) {
    WITHOUT_RECORD(fmi2Status, fmi2SetRealInputDerivatives(instance, vr, nvr, order, value))
    RECORD_VALUES((Status)status, vr, order, nvr, value)
    return status;
}

static NOINLINE fmi2Status recorded_do_step(Instance *instance, const char *function,
                                            double communication_point, double communication_step,
                                            fmi2Boolean no_set_state_prior) {
    WITHOUT_RECORD(fmi2Status, fmi2DoStep(instance, communication_point, communication_step, no_set_state_prior))
    RECORD((Status)status, "currentCommunicationPoint=%.17g, communicationStepSize=%.17g",
           communication_point, communication_step)
    return status;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; /* the model needs no resources */
    (void)visible;
    static const char function[] = "fmi2Instantiate";
    if (!functions) return NULL;
    const Logger logger = {forward_to_fmi2_logger, (AnyFunction)functions->logger,
                           functions->componentEnvironment};
    if (fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange)
        return instance_refuse(function, instanceName, &logger, "fmuType %d is neither "
                               "fmi2ModelExchange (0) nor fmi2CoSimulation (1)", (int)fmuType);
    return instance_create(function, instanceName, "fmuGUID", fmuGUID,
                           fmuType == fmi2CoSimulation ? INTERFACE_CO_SIMULATION
                                                       : INTERFACE_MODEL_EXCHANGE,
                           &logger, loggingOn);
}

void fmi2FreeInstance(fmi2Component c) {
    static const char function[] = "fmi2FreeInstance";
    Instance *instance = (Instance *)c;
    if (instance) {
        const double time_before = instance->data.time;
        RECORD(STATUS_OK, "")
    }
    instance_free(instance);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    ENTER(fmi2SetDebugLogging)
    return STATUS(instance_set_debug_logging(instance, function, loggingOn, nCategories, categories));
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    /* stopTime is only recorded: a model without events has no end of its own. */
    ENTER(fmi2SetupExperiment)
    KEEP_TIME
    const Status status = instance_setup_experiment(instance, function, toleranceDefined, tolerance,
                                                    startTime);
    RECORD(status, "toleranceDefined=%d, tolerance=%.17g, startTime=%.17g, stopTimeDefined=%d, "
           "stopTime=%.17g", (int)toleranceDefined, tolerance, startTime, (int)stopTimeDefined, stopTime)
    return STATUS(status);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    ENTER(fmi2EnterInitializationMode)
    KEEP_TIME
    instance->data.machine_state = STATE_INITIALIZATION_MODE;
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    ENTER(fmi2ExitInitializationMode)
    KEEP_TIME
    const Status status = instance_exit_initialization(instance, function);
    RECORD(status, "")
    return STATUS(status);
}

fmi2Status fmi2Terminate(fmi2Component c) {
    ENTER(fmi2Terminate)
    KEEP_TIME
    instance->data.machine_state = STATE_TERMINATED;
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    ENTER(fmi2Reset)
    KEEP_TIME
    instance_reset(instance);
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    ENTER(fmi2GetReal)
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(value, nvr)
    if (instance_recording(instance))
        return recorded_get_real(instance, function, vr, nvr, value);
    return STATUS(instance_get_real(instance, function, vr, nvr, value));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    ENTER(fmi2SetReal)
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(value, nvr)
    if (instance_recording(instance)) return recorded_set_real(instance, function, vr, nvr, value);
    return STATUS(instance_set_real(instance, function, vr, nvr, value));
}

/* The model has Real variables and String parameters only: any Integer or Boolean reference is
   unknown. */
#define NO_VARIABLES_OF_TYPE(name, type)                                                   \
    fmi2Status name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, type value) { \
        (void)value;                                                                     \
        ENTER(name)                                                                      \
        REQUIRE_ARRAY(vr, nvr)                                                           \
        if (nvr == 0) return fmi2OK;                                                     \
        return STATUS(instance_error(instance, function,                                 \
                                     "vr %u: this FMU has no variables of this type", vr[0])); \
    }

NO_VARIABLES_OF_TYPE(fmi2GetInteger, fmi2Integer *)
NO_VARIABLES_OF_TYPE(fmi2GetBoolean, fmi2Boolean *)
NO_VARIABLES_OF_TYPE(fmi2SetInteger, const fmi2Integer *)
NO_VARIABLES_OF_TYPE(fmi2SetBoolean, const fmi2Boolean *)

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    ENTER(fmi2GetString)
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(value, nvr)
    return STATUS(instance_get_string(instance, function, vr, nvr, value));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    ENTER(fmi2SetString)
    KEEP_TIME
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(value, nvr)
    const Status status = instance_set_string(instance, function, vr, nvr, value);
    char file[ESCAPED_SIZE(MAX_RECORD_FILE_NAME)];
    RECORD(status, "file=\"%s\"", escape_text(file, sizeof(file), instance->record_file_name))
    return STATUS(status);
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    ENTER(fmi2GetFMUstate)
    KEEP_TIME
    const Status status = instance_get_state(instance, function, FMUstate);
    RECORD(status, "state=%p", (void *)(FMUstate ? *FMUstate : NULL))
    return STATUS(status);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    ENTER(fmi2SetFMUstate)
    KEEP_TIME
    const Status status = instance_set_state(instance, function, FMUstate);
    RECORD(status, "state=%p", (void *)(FMUstate))
    return STATUS(status);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    ENTER(fmi2FreeFMUstate)
    KEEP_TIME
    void *const freed = FMUstate ? *FMUstate : NULL;
    const Status status = instance_free_state(instance, function, FMUstate);
    RECORD(status, "state=%p", freed)
    return STATUS(status);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    ENTER(fmi2SerializedFMUstateSize)
    KEEP_TIME
    const Status status = instance_serialized_state_size(instance, function, FMUstate, size);
    RECORD(status, "state=%p", (void *)(FMUstate))
    return STATUS(status);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                 size_t size) {
    ENTER(fmi2SerializeFMUstate)
    KEEP_TIME
    const Status status = instance_serialize_state(instance, function, FMUstate,
                                                   (unsigned char *)serializedState, size);
    RECORD(status, "state=%p, size=%lu", (void *)FMUstate, (unsigned long)size)
    return STATUS(status);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate) {
    ENTER(fmi2DeSerializeFMUstate)
    KEEP_TIME
    const Status status = instance_deserialize_state(instance, function,
                                                     (const unsigned char *)serializedState, size,
                                                     FMUstate);
    RECORD(status, "size=%lu, state=%p", (unsigned long)size, (void *)(FMUstate ? *FMUstate : NULL))
    return STATUS(status);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    ENTER(fmi2GetDirectionalDerivative)
    REQUIRE_ARRAY(vUnknown_ref, nUnknown)
    REQUIRE_ARRAY(dvUnknown, nUnknown)
    REQUIRE_ARRAY(vKnown_ref, nKnown)
    REQUIRE_ARRAY(dvKnown, nKnown)
    return STATUS(instance_directional_derivative(instance, function, vUnknown_ref, nUnknown,
                                                  vKnown_ref, nKnown, dvKnown, dvUnknown));
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    ENTER(fmi2SetRealInputDerivatives)
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(order, nvr)
    REQUIRE_ARRAY(value, nvr)
    if (instance_recording(instance))
        return recorded_input_derivatives(instance, function, vr, nvr, order, value);
    return STATUS(instance_set_input_derivatives(instance, function, vr, nvr, order, value));
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    ENTER(fmi2GetRealOutputDerivatives)
    REQUIRE_ARRAY(vr, nvr)
    REQUIRE_ARRAY(order, nvr)
    REQUIRE_ARRAY(value, nvr)
    return STATUS(instance_get_output_derivatives(instance, function, vr, nvr, order, value));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    /* noSetFMUStatePriorToCurrentPoint only passes through: states are copies, nothing to release
       early. */
    ENTER(fmi2DoStep)
    if (instance_recording(instance))
        return recorded_do_step(instance, function, currentCommunicationPoint, communicationStepSize,
                                noSetFMUStatePriorToCurrentPoint);
    return STATUS(instance_do_step(instance, function, currentCommunicationPoint,
                                   communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    ENTER(fmi2CancelStep)
    return fmi2Error; /* unreachable: steps are never asynchronous, so no state allows it */
}

/* Only fmi2LastSuccessfulTime and fmi2Terminated mean anything for a synchronous slave. */
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    ENTER(fmi2GetStatus)
    (void)s;
    (void)value;
    return STATUS(instance_error(instance, function, "no status of this kind: steps are synchronous"));
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    ENTER(fmi2GetRealStatus)
    if (instance_null_argument(instance, function, "value", value)) return fmi2Error;
    if (s != fmi2LastSuccessfulTime)
        return STATUS(instance_error(instance, function, "only fmi2LastSuccessfulTime is available"));
    *value = instance->data.last_successful_time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    ENTER(fmi2GetIntegerStatus)
    (void)s;
    (void)value;
    return STATUS(instance_error(instance, function, "no integer status is available"));
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    ENTER(fmi2GetBooleanStatus)
    if (instance_null_argument(instance, function, "value", value)) return fmi2Error;
    if (s != fmi2Terminated)
        return STATUS(instance_error(instance, function, "only fmi2Terminated is available"));
    *value = fmi2False; /* a model without events never asks to stop */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    ENTER(fmi2GetStringStatus)
    (void)s;
    (void)value;
    return STATUS(instance_error(instance, function, "no string status is available"));
}

/* Model exchange, for a model without events (HAS_EVENTS 0 in its config.h): event mode only
   passes through. */
#if HAS_EVENTS
#error "HAS_EVENTS 1: the FMI plumbing has no event indicators or discrete states yet"
#endif

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    ENTER(fmi2EnterEventMode)
    KEEP_TIME
    instance->data.machine_state = STATE_EVENT_MODE;
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *fmi2eventInfo) {
    ENTER(fmi2NewDiscreteStates)
    if (instance_null_argument(instance, function, "fmi2eventInfo", fmi2eventInfo)) return fmi2Error;
    fmi2eventInfo->newDiscreteStatesNeeded = fmi2False;
    fmi2eventInfo->terminateSimulation = fmi2False;
    fmi2eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    fmi2eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    fmi2eventInfo->nextEventTimeDefined = fmi2False;
    fmi2eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    ENTER(fmi2EnterContinuousTimeMode)
    KEEP_TIME
    instance->data.machine_state = STATE_CONTINUOUS_TIME_MODE;
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(fmi2CompletedIntegratorStep)
    KEEP_TIME
    if (instance_null_argument(instance, function, "enterEventMode", enterEventMode) ||
        instance_null_argument(instance, function, "terminateSimulation", terminateSimulation))
        return fmi2Error;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    RECORD(STATUS_OK, "")
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    ENTER(fmi2SetTime)
    KEEP_TIME
    const Status status = instance_set_time(instance, function, time);
    RECORD(status, "time=%.17g", time)
    return STATUS(status);
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    ENTER(fmi2SetContinuousStates)
    KEEP_TIME
    REQUIRE_ARRAY(x, nx)
    const Status status = instance_set_states(instance, function, x, nx);
    RECORD_VALUES(status, NULL, NULL, status == STATUS_OK ? nx : 0, x)
    return STATUS(status);
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    ENTER(fmi2GetDerivatives)
    KEEP_TIME
    REQUIRE_ARRAY(derivatives, nx)
    const Status status = instance_get_derivatives(instance, function, derivatives, nx);
    RECORD_VALUES(status, NULL, NULL, status == STATUS_OK ? nx : 0, derivatives)
    return STATUS(status);
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    ENTER(fmi2GetEventIndicators)
    if (ni == 0) return fmi2OK;
    return STATUS(instance_error(instance, function, "ni = %lu, but the model has no event indicators",
                                 (unsigned long)ni));
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    ENTER(fmi2GetContinuousStates)
    REQUIRE_ARRAY(x, nx)
    return STATUS(instance_get_states(instance, function, x, nx));
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    ENTER(fmi2GetNominalsOfContinuousStates)
    REQUIRE_ARRAY(x_nominal, nx)
    return STATUS(instance_get_nominals(instance, function, x_nominal, nx));
}
