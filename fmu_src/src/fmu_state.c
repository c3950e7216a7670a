/* FMU states: in memory a copy of InstanceData in its instance's list of the states it handed
   out, so that a pointer the master passes back is checked before it is read; serialized, a
   versioned blob that is checked to the last byte before anything in it is believed:
       magic "PNDL" | format version u32 | payload size u32 | payload (InstanceData) | FNV-1a 64 */

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "instance.h"

#define STATE_MAGIC "PNDL"
/* 2: inputs carry first and second derivatives. */
#define STATE_FORMAT_VERSION 2u
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

/* States past initialization, where the parameters have passed the model's checks. */
#define INITIALIZED_STATES (RESTORABLE_STATES & ~(STATE_INSTANTIATED | STATE_INITIALIZATION_MODE))

/* NULL when data could have come from an instance of this FMU, else what is wrong with it. */
static const char *implausible(const InstanceData *data) {
    const int64_t state = data->machine_state;
    if (!(state & RESTORABLE_STATES) || (state & ~(int64_t)RESTORABLE_STATES) || (state & (state - 1)))
        return "unknown machine state";
    if (!isfinite(data->time) || !isfinite(data->last_successful_time)) return "non-finite time";
    if (!(data->tolerance > 0 && data->tolerance < 1)) return "tolerance out of range";
    /* +inf is a hint like any other: a step near the largest double, at rest, grows it there. */
    if (!(data->step_size >= 0)) return "bad internal step size";
    for (size_t vr = 0; vr < N_VARIABLES; vr++) {
        const double first = data->inputs.first[vr], second = data->inputs.second[vr];
        if (!isfinite(data->values[vr]) || !isfinite(first) || !isfinite(second))
            return "non-finite value";
        if ((first != 0 || second != 0) && model_variables[vr].causality != CAUSALITY_INPUT)
            return "derivative on a variable that is not an input";
    }
    /* Before initialization ends the parameters are the master's, not checked yet. */
    if ((state & INITIALIZED_STATES) && model_invalid_parameters(data->values))
        return "parameters no initialization would accept";
    return NULL;
}

/* A state as this FMU hands it out, linked into its instance's list. The data comes first: a
   master that passes the state where the address of its variable belongs (fmusim 0.0.39 calls
   fmi2FreeFMUstate(c, state)) makes us read a machine state, never the address of a state. */
typedef struct StoredState {
    InstanceData data;
    struct StoredState *next;
} StoredState;

/* The link that holds state in the instance's list, or NULL when the instance did not hand it
   out. Addresses are only compared, so a foreign pointer is never read. */
static StoredState **link_to(Instance *instance, const void *state) {
    for (StoredState **link = &instance->states; *link; link = &(*link)->next)
        if ((const void *)*link == state) return link;
    return NULL;
}

static Status refuse_foreign(const Instance *instance, const char *function) {
    return instance_error(instance, function, "FMUstate is not a state this instance handed out "
                          "(freed already, another instance's, or no state at all): refused, the "
                          "instance is unchanged");
}

/* The instance's own state at that address, or NULL after logging why it is refused. */
static StoredState *own_state(Instance *instance, const char *function, const void *state) {
    StoredState **link = link_to(instance, state);
    if (link) return *link;
    refuse_foreign(instance, function);
    return NULL;
}

/* The state the master hands back to be overwritten (*state), or a new one in the list. */
static StoredState *state_to_fill(Instance *instance, const char *function, void *state) {
    if (state) return own_state(instance, function, state);
    if (instance->n_states >= MAX_FMU_STATES) {
        instance_error(instance, function, "this instance holds %d FMU states, the most it keeps: "
                       "free those no longer needed", MAX_FMU_STATES);
        return NULL;
    }
    StoredState *stored = malloc(sizeof(StoredState));
    if (!stored) {
        instance_error(instance, function, "out of memory");
        return NULL;
    }
    stored->next = instance->states;
    instance->states = stored;
    instance->n_states++;
    return stored;
}

Status instance_get_state(Instance *instance, const char *function, void **state) {
    if (instance_null_argument(instance, function, "FMUstate", state)) return STATUS_ERROR;
    StoredState *stored = state_to_fill(instance, function, *state);
    if (!stored) return STATUS_ERROR;
    stored->data = instance->data;
    *state = stored;
    return STATUS_OK;
}

Status instance_set_state(Instance *instance, const char *function, const void *state) {
    if (instance_null_argument(instance, function, "FMUstate", state)) return STATUS_ERROR;
    const StoredState *stored = own_state(instance, function, state);
    if (!stored) return STATUS_ERROR;
    const InstanceData *data = &stored->data;
    const int own_states = instance->type == INTERFACE_CO_SIMULATION ? CO_SIMULATION_STATES
                                                                       : MODEL_EXCHANGE_STATES;
    if (!(data->machine_state & own_states))
        return instance_error(instance, function,
                              "the state comes from an instance of the other FMI interface");
    instance->data = *data;
    instance_data_changed(instance);
    return STATUS_OK;
}

Status instance_free_state(Instance *instance, const char *function, void **state) {
    if (instance_null_argument(instance, function, "FMUstate", state)) return STATUS_ERROR;
    /* The usual call first, one pass over the list. Where state is one of ours itself, *state
       reads its machine state (StoredState's first field), which is no state's address. */
    StoredState **link = *state ? link_to(instance, *state) : NULL;
    if (!link) {
        if (link_to(instance, state))
            return instance_error(instance, function, "FMUstate is a state itself, where the address "
                                  "of the variable that holds it belongs (%s(instance, &state)): "
                                  "refused, nothing freed", function);
        if (!*state) return STATUS_OK; /* both standards: freeing NULL is ignored */
        return refuse_foreign(instance, function);
    }
    StoredState *stored = *link;
    *link = stored->next;
    free(stored);
    instance->n_states--;
    *state = NULL;
    return STATUS_OK;
}

void instance_free_states(Instance *instance) {
    while (instance->states) {
        StoredState *next = instance->states->next;
        free(instance->states);
        instance->states = next;
    }
    instance->n_states = 0;
}

Status instance_serialized_state_size(Instance *instance, const char *function, const void *state,
                                      size_t *size) {
    if (instance_null_argument(instance, function, "FMUstate", state) ||
        instance_null_argument(instance, function, "size", size) ||
        !own_state(instance, function, state))
        return STATUS_ERROR;
    *size = SERIALIZED_SIZE;
    return STATUS_OK;
}

Status instance_serialize_state(Instance *instance, const char *function, const void *state,
                                unsigned char bytes[], size_t size) {
    if (instance_null_argument(instance, function, "FMUstate", state) ||
        instance_null_argument(instance, function, "serializedState", bytes))
        return STATUS_ERROR;
    const StoredState *stored = own_state(instance, function, state);
    if (!stored) return STATUS_ERROR;
    if (size < SERIALIZED_SIZE)
        return instance_error(instance, function, "size %lu is too small: %lu bytes needed",
                              (unsigned long)size, (unsigned long)SERIALIZED_SIZE);
    unsigned char *out = bytes;
    memcpy(out, STATE_MAGIC, 4);
    put_u32(out + 4, STATE_FORMAT_VERSION);
    put_u32(out + 8, (uint32_t)sizeof(InstanceData));
    memcpy(out + HEADER_SIZE, &stored->data, sizeof(InstanceData));
    const uint64_t checksum = fnv1a(out, HEADER_SIZE + sizeof(InstanceData));
    memcpy(out + HEADER_SIZE + sizeof(InstanceData), &checksum, CHECKSUM_SIZE);
    return STATUS_OK;
}

Status instance_deserialize_state(Instance *instance, const char *function,
                                  const unsigned char bytes[], size_t size, void **state) {
    if (instance_null_argument(instance, function, "serializedState", bytes) ||
        instance_null_argument(instance, function, "FMUstate", state))
        return STATUS_ERROR;
    const unsigned char *in = bytes;
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

    StoredState *stored = state_to_fill(instance, function, *state);
    if (!stored) return STATUS_ERROR;
    stored->data = data;
    *state = stored;
    return STATUS_OK;
}
