/* FMU states: in memory a copy of InstanceData; serialized, a versioned blob that is checked to
   the last byte before anything in it is believed:
       magic "PNDL" | format version u32 | payload size u32 | payload (InstanceData) | FNV-1a 64 */

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"

#define STATE_MAGIC "PNDL"
#define STATE_FORMAT_VERSION 1u
#define HEADER_SIZE 12u
#define CHECKSUM_SIZE 8u
#define SERIALIZED_SIZE (HEADER_SIZE + sizeof(InstanceData) + CHECKSUM_SIZE)

/* States an FMU state may be taken in and restored to. */
#define RESTORABLE_STATES (CO_SIMULATION_STATES | MODEL_EXCHANGE_STATES)

static uint64_t fnv1a(const unsigned char *bytes, size_t size) {
    uint64_t hash = 14695981039346656037ull;
    for (size_t i = 0; i < size; i++) {
        hash ^= bytes[i];
        hash *= 1099511628211ull;
    }
    return hash;
}

static void put_u32(unsigned char *to, uint32_t value) { memcpy(to, &value, sizeof(value)); }

static uint32_t get_u32(const unsigned char *from) {
    uint32_t value;
    memcpy(&value, from, sizeof(value));
    return value;
}

/* NULL when data could have come from an instance of this FMU, else what is wrong with it. */
static const char *implausible(const InstanceData *data) {
    const int state = data->machine_state;
    if (!(state & RESTORABLE_STATES) || (state & (state - 1))) return "unknown machine state";
    if (!isfinite(data->time) || !isfinite(data->last_successful_time)) return "non-finite time";
    if (!(data->tolerance > 0 && data->tolerance < 1)) return "tolerance out of range";
    if (!(data->step_size >= 0) || !isfinite(data->step_size)) return "bad internal step size";
    for (size_t vr = 0; vr < N_VARIABLES; vr++) {
        if (!isfinite(data->values[vr]) || !isfinite(data->input_rates[vr])) return "non-finite value";
        if (data->input_rates[vr] != 0 && model_variables[vr].causality != CAUSALITY_INPUT)
            return "rate on a variable that is not an input";
    }
    return NULL;
}

fmi2Status instance_get_state(Instance *instance, fmi2FMUstate *state) {
    if (instance_null_argument(instance, "fmi2GetFMUstate", "FMUstate", state)) return fmi2Error;
    /* The master may hand back a state it got before: overwrite it in place. */
    InstanceData *copy = *state ? (InstanceData *)*state : malloc(sizeof(InstanceData));
    if (!copy) return instance_error(instance, "fmi2GetFMUstate", "out of memory");
    *copy = instance->data;
    *state = copy;
    return fmi2OK;
}

fmi2Status instance_set_state(Instance *instance, fmi2FMUstate state) {
    if (instance_null_argument(instance, "fmi2SetFMUstate", "FMUstate", state)) return fmi2Error;
    const InstanceData *data = state;
    const int own_states = instance->type == fmi2CoSimulation ? CO_SIMULATION_STATES
                                                                : MODEL_EXCHANGE_STATES;
    if (!(data->machine_state & own_states))
        return instance_error(instance, "fmi2SetFMUstate",
                              "the state comes from an instance of the other FMI interface");
    instance->data = *data;
    instance_data_changed(instance);
    return fmi2OK;
}

fmi2Status instance_free_state(Instance *instance, fmi2FMUstate *state) {
    if (instance_null_argument(instance, "fmi2FreeFMUstate", "FMUstate", state)) return fmi2Error;
    free(*state);
    *state = NULL;
    return fmi2OK;
}

fmi2Status instance_serialized_state_size(Instance *instance, fmi2FMUstate state, size_t *size) {
    if (instance_null_argument(instance, "fmi2SerializedFMUstateSize", "FMUstate", state) ||
        instance_null_argument(instance, "fmi2SerializedFMUstateSize", "size", size))
        return fmi2Error;
    *size = SERIALIZED_SIZE;
    return fmi2OK;
}

fmi2Status instance_serialize_state(Instance *instance, fmi2FMUstate state, fmi2Byte bytes[],
                                    size_t size) {
    const char *function = "fmi2SerializeFMUstate";
    if (instance_null_argument(instance, function, "FMUstate", state) ||
        instance_null_argument(instance, function, "serializedState", bytes))
        return fmi2Error;
    if (size < SERIALIZED_SIZE)
        return instance_error(instance, function, "size %lu is too small: %lu bytes needed",
                              (unsigned long)size, (unsigned long)SERIALIZED_SIZE);
    unsigned char *out = (unsigned char *)bytes;
    memcpy(out, STATE_MAGIC, 4);
    put_u32(out + 4, STATE_FORMAT_VERSION);
    put_u32(out + 8, (uint32_t)sizeof(InstanceData));
    memcpy(out + HEADER_SIZE, state, sizeof(InstanceData));
    const uint64_t checksum = fnv1a(out, HEADER_SIZE + sizeof(InstanceData));
    memcpy(out + HEADER_SIZE + sizeof(InstanceData), &checksum, CHECKSUM_SIZE);
    return fmi2OK;
}

fmi2Status instance_deserialize_state(Instance *instance, const fmi2Byte bytes[], size_t size,
                                      fmi2FMUstate *state) {
    const char *function = "fmi2DeSerializeFMUstate";
    if (instance_null_argument(instance, function, "serializedState", bytes) ||
        instance_null_argument(instance, function, "FMUstate", state))
        return fmi2Error;
    const unsigned char *in = (const unsigned char *)bytes;
    if (size < HEADER_SIZE || memcmp(in, STATE_MAGIC, 4) != 0)
        return instance_error(instance, function, "not a serialized state of this FMU (bad magic)");
    if (get_u32(in + 4) != STATE_FORMAT_VERSION)
        return instance_error(instance, function, "state format version %u, this FMU reads %u",
                              get_u32(in + 4), STATE_FORMAT_VERSION);
    if (get_u32(in + 8) != sizeof(InstanceData) || size != SERIALIZED_SIZE)
        return instance_error(instance, function,
                              "%lu bytes with payload %u, expected %lu with payload %lu "
                              "(truncated, or from another build)", (unsigned long)size,
                              get_u32(in + 8), (unsigned long)SERIALIZED_SIZE,
                              (unsigned long)sizeof(InstanceData));
    uint64_t checksum;
    memcpy(&checksum, in + HEADER_SIZE + sizeof(InstanceData), CHECKSUM_SIZE);
    if (checksum != fnv1a(in, HEADER_SIZE + sizeof(InstanceData)))
        return instance_error(instance, function, "checksum mismatch: the bytes are corrupt");
    InstanceData data;
    memcpy(&data, in + HEADER_SIZE, sizeof(data));
    const char *problem = implausible(&data);
    if (problem) return instance_error(instance, function, "implausible state: %s", problem);

    InstanceData *copy = *state ? (InstanceData *)*state : malloc(sizeof(InstanceData));
    if (!copy) return instance_error(instance, function, "out of memory");
    *copy = data;
    *state = copy;
    return fmi2OK;
}
