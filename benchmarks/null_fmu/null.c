/* The floor: an FMU with the pendulum's torque/theta interface whose fmi2DoStep does nothing.
   Driving it costs what the master and the FMI calls cost, so timing it beside the pendulum
   shows what the pendulum itself adds. Every function exists because fmpy binds them all. */

#include <stdlib.h>

#include "fmi2Functions.h"

/* It ignores almost every argument by design. */
#pragma GCC diagnostic ignored "-Wunused-parameter"

#define N_VARIABLES 2 /* torque (vr 0) and theta (vr 1), as in the pendulum */

typedef struct {
    double values[N_VARIABLES];
} NullInstance;

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                              fmi2String resources, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean logging_on) {
    return calloc(1, sizeof(NullInstance));
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

/* Copying values is the least a real FMU does, so the floor does it too. */
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    NullInstance *instance = c;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES) return fmi2Error;
        instance->values[vr[i]] = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    const NullInstance *instance = c;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_VARIABLES) return fmi2Error;
        value[i] = instance->values[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real time, fmi2Real step, fmi2Boolean no_rollback) {
    return fmi2OK;
}

/* The rest accept anything and do nothing. */
#define NOTHING(function, ...) \
    fmi2Status function(__VA_ARGS__) { return fmi2OK; }

NOTHING(fmi2SetDebugLogging, fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[])
NOTHING(fmi2SetupExperiment, fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
        fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop)
NOTHING(fmi2EnterInitializationMode, fmi2Component c)
NOTHING(fmi2ExitInitializationMode, fmi2Component c)
NOTHING(fmi2Terminate, fmi2Component c)
NOTHING(fmi2Reset, fmi2Component c)
NOTHING(fmi2GetInteger, fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
NOTHING(fmi2GetBoolean, fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
NOTHING(fmi2GetString, fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
NOTHING(fmi2SetInteger, fmi2Component c, const fmi2ValueReference vr[], size_t n,
        const fmi2Integer v[])
NOTHING(fmi2SetBoolean, fmi2Component c, const fmi2ValueReference vr[], size_t n,
        const fmi2Boolean v[])
NOTHING(fmi2SetString, fmi2Component c, const fmi2ValueReference vr[], size_t n,
        const fmi2String v[])
NOTHING(fmi2GetFMUstate, fmi2Component c, fmi2FMUstate *state)
NOTHING(fmi2SetFMUstate, fmi2Component c, fmi2FMUstate state)
NOTHING(fmi2FreeFMUstate, fmi2Component c, fmi2FMUstate *state)
NOTHING(fmi2SerializedFMUstateSize, fmi2Component c, fmi2FMUstate state, size_t *size)
NOTHING(fmi2SerializeFMUstate, fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
NOTHING(fmi2DeSerializeFMUstate, fmi2Component c, const fmi2Byte bytes[], size_t size,
        fmi2FMUstate *state)
NOTHING(fmi2GetDirectionalDerivative, fmi2Component c, const fmi2ValueReference unknown[],
        size_t n_unknown, const fmi2ValueReference known[], size_t n_known,
        const fmi2Real known_delta[], fmi2Real unknown_delta[])
NOTHING(fmi2SetRealInputDerivatives, fmi2Component c, const fmi2ValueReference vr[], size_t n,
        const fmi2Integer order[], const fmi2Real v[])
NOTHING(fmi2GetRealOutputDerivatives, fmi2Component c, const fmi2ValueReference vr[], size_t n,
        const fmi2Integer order[], fmi2Real v[])
NOTHING(fmi2CancelStep, fmi2Component c)
NOTHING(fmi2GetStatus, fmi2Component c, const fmi2StatusKind s, fmi2Status *v)
NOTHING(fmi2GetRealStatus, fmi2Component c, const fmi2StatusKind s, fmi2Real *v)
NOTHING(fmi2GetIntegerStatus, fmi2Component c, const fmi2StatusKind s, fmi2Integer *v)
NOTHING(fmi2GetBooleanStatus, fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v)
NOTHING(fmi2GetStringStatus, fmi2Component c, const fmi2StatusKind s, fmi2String *v)
