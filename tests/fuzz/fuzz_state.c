/* libFuzzer harness for fmi2DeSerializeFMUstate and fmi3DeserializeFMUState. The first byte's
   lowest bit picks what the rest is:
   0: raw bytes as the blob;
   1: a valid blob with the bytes XORed over its payload and the checksum then repaired, so the
      plausibility checks behind the checksum, and stepping from what passes them, get fuzzed;
   and its next bit the standard whose entry points take it. */

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"
#include "model_variables.h"

static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e, (void)n, (void)s, (void)c, (void)m;
}

static const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};

static void logger3(fmi3InstanceEnvironment e, fmi3Status s, fmi3String c, fmi3String m) {
    (void)e, (void)s, (void)c, (void)m;
}

static fmi2Component instance;
static fmi3Instance instance3;
static fmi2Byte *valid;
static size_t valid_size;

/* The format's checksum (fmu_state.c): FNV-1a 64 over everything before it. */
static uint64_t fnv1a(const unsigned char *bytes, size_t size) {
    uint64_t hash = 14695981039346656037ull;
    for (size_t i = 0; i < size; i++) hash = (hash ^ bytes[i]) * 1099511628211ull;
    return hash;
}

static void setup(void) {
    instance = fmi2Instantiate("fuzz", fmi2CoSimulation, MODEL_GUID, "", &callbacks, fmi2False, fmi2False);
    fmi2SetupExperiment(instance, fmi2False, 0, 0, fmi2False, 0);
    fmi2EnterInitializationMode(instance);
    fmi2ExitInitializationMode(instance);
    fmi2DoStep(instance, 0, 0.01, fmi2True);
    fmi2FMUstate state = NULL;
    fmi2GetFMUstate(instance, &state);
    fmi2SerializedFMUstateSize(instance, state, &valid_size);
    valid = malloc(valid_size);
    fmi2SerializeFMUstate(instance, state, valid, valid_size);
    fmi2FreeFMUstate(instance, &state);
    instance3 = fmi3InstantiateCoSimulation("fuzz3", MODEL_GUID, "", fmi3False, fmi3False, fmi3False, fmi3False,
                                            NULL, 0, NULL, logger3, NULL);
    fmi3EnterInitializationMode(instance3, fmi3False, 0, 0, fmi3False, 0);
    fmi3ExitInitializationMode(instance3);
}

/* The FMI 3.0 path of the same checks: whatever passes must be safe to restore and step from. */
static void deserialize_fmi3(const fmi3Byte *blob, size_t blob_size) {
    fmi3FMUState state = NULL;
    if (fmi3DeserializeFMUState(instance3, blob, blob_size, &state) != fmi3OK) return;
    const fmi3ValueReference time_vr = N_VARIABLES; /* the independent variable */
    fmi3Boolean event, terminate, early;
    double time, last;
    fmi3SetFMUState(instance3, state);
    if (fmi3GetFloat64(instance3, &time_vr, 1, &time, 1) == fmi3OK)
        fmi3DoStep(instance3, time, 1e-3, fmi3True, &event, &terminate, &early, &last);
    fmi3FreeFMUState(instance3, &state);
    fmi3Reset(instance3);
    fmi3EnterInitializationMode(instance3, fmi3False, 0, 0, fmi3False, 0);
    fmi3ExitInitializationMode(instance3);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (!instance) setup();
    if (size == 0) return 0;
    fmi2Byte *blob;
    size_t blob_size;
    if (data[0] % 2 == 0) {
        blob_size = size - 1;
        blob = malloc(blob_size ? blob_size : 1);  /* exactly the bytes: ASan sees any overread */
        memcpy(blob, data + 1, blob_size);
    } else {
        blob_size = valid_size;
        blob = malloc(blob_size);
        memcpy(blob, valid, blob_size);
        for (size_t i = 1; i < size && 12 + i - 1 < valid_size - 8; i++) blob[12 + i - 1] ^= data[i];
        const uint64_t checksum = fnv1a((const unsigned char *)blob, valid_size - 8);
        memcpy(blob + valid_size - 8, &checksum, 8);
    }
    fmi2FMUstate state = NULL;
    if (data[0] & 2) {
        deserialize_fmi3((const fmi3Byte *)blob, blob_size);
    } else if (fmi2DeSerializeFMUstate(instance, blob, blob_size, &state) == fmi2OK) {
        /* Whatever passes must be safe to restore and step from. */
        const fmi2ValueReference theta = VR_THETA;
        double value, time;
        fmi2SetFMUstate(instance, state);
        if (fmi2GetRealStatus(instance, fmi2LastSuccessfulTime, &time) == fmi2OK)
            fmi2DoStep(instance, time, 1e-3, fmi2True);
        fmi2GetReal(instance, &theta, 1, &value);
        fmi2FreeFMUstate(instance, &state);
        fmi2Reset(instance);
        fmi2SetupExperiment(instance, fmi2False, 0, 0, fmi2False, 0);
        fmi2EnterInitializationMode(instance);
        fmi2ExitInitializationMode(instance);
    }
    free(blob);
    return 0;
}
