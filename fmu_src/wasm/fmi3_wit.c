/* The FMI 3.0 C API as FMI-LS-WASM's WIT interfaces (fmi:fmi3@3.0.0, wit/deps/fmi3/): each
   fmi3_wit_* function of wit_glue.h (generated from the WIT by fmu_build/wasm_glue.py, which also
   writes the canonical ABI's lifting and lowering) calls the fmi3* function it maps, so the
   component computes exactly what the native FMI 3.0 binary does. It knows nothing of the model,
   and nothing of the Component Model beyond wit_glue.h's C types.

   The draft's mapping, as done here: an instance is a resource whose representation is a
   WitInstance (the fmi3Instance and its name, which log-message passes back); dropping it is
   fmi3FreeInstance. Lists become C arrays, strings NUL-terminated copies, option<f64> the
   defined flag and its value. A result<T, status> is ok for fmi3OK and fmi3Warning (the warning's
   message has gone through log-message already), else the status. get-fmu-state is
   fmi3GetFMUState, fmi3SerializeFMUState and fmi3FreeFMUState in one; set-fmu-state
   fmi3DeserializeFMUState, fmi3SetFMUState and fmi3FreeFMUState. Memory running out traps: the
   canonical ABI has no way to say so. */

#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "wit_glue.h"

struct WitInstance {
    fmi3Instance instance;
    char *name; /* as log-message passes it back */
};

static void *allocate(size_t count, size_t size) {
    if (count == 0) return NULL;
    void *memory = calloc(count, size);
    if (!memory) abort();
    return memory;
}

/* A NUL-terminated copy of a WIT string (cut at a NUL inside it, as C reads it). */
static char *c_string(wit_string_t text) {
    char *copy = allocate(text.len + 1, 1);
    memcpy(copy, text.ptr, text.len);
    return copy;
}

static wit_string_t wit_string(const char *text) {
    const size_t length = text ? strlen(text) : 0;
    wit_string_t copy = {allocate(length, 1), length};
    if (length) memcpy(copy.ptr, text, length);
    return copy;
}

/* NUL-terminated copies of a list of WIT strings, freed by free_c_strings. */
static char **c_strings(wit_list_string_t texts) {
    char **copies = allocate(texts.len, sizeof(char *));
    for (size_t i = 0; i < texts.len; i++) copies[i] = c_string(texts.ptr[i]);
    return copies;
}

static void free_c_strings(char **copies, size_t count) {
    for (size_t i = 0; i < count; i++) free(copies[i]);
    free(copies);
}

/* Whether a status gives a result (OK, or Warning with its message already logged). */
static bool succeeded(fmi3Status status) { return status == fmi3OK || status == fmi3Warning; }

/* Fills a result<list<T>, status> with values (count of them) or the status; frees values when failed. */
#define LIST_RESULT(ret, status, values, count)                                        \
    do {                                                                               \
        if (succeeded(status)) {                                                       \
            (ret)->is_err = false;                                                     \
            (ret)->val.ok.ptr = (values);                                              \
            (ret)->val.ok.len = (count);                                               \
        } else {                                                                       \
            free(values);                                                              \
            (ret)->is_err = true;                                                      \
            (ret)->val.err = (uint8_t)(status);                                        \
        }                                                                              \
    } while (0)

static void forward_log_message(fmi3InstanceEnvironment environment, fmi3Status status,
                                fmi3String category, fmi3String message) {
    const WitInstance *self = environment;
    /* Borrowed, not copied: the host copies the strings out during the call. */
    const wit_string_t name = {(uint8_t *)self->name, strlen(self->name)};
    const wit_string_t category_text = {(uint8_t *)(category ? category : ""), category ? strlen(category) : 0};
    const wit_string_t message_text = {(uint8_t *)(message ? message : ""), message ? strlen(message) : 0};
    fmi3_wit_log_message(name, (uint8_t)status, category_text, message_text);
}

/* fmi3Error, with why logged as the native functions log theirs, for what the WIT allows and no
   C function takes. */
static uint8_t refuse(const WitInstance *self, const char *why) {
    forward_log_message((fmi3InstanceEnvironment)self, fmi3Error, "logStatusError", why);
    return (uint8_t)fmi3Error;
}

void fmi3_wit_get_version(wit_string_t *ret) { *ret = wit_string(fmi3GetVersion()); }

/* A WitInstance with its name, before the instance: the logger may speak during instantiation. */
static WitInstance *new_instance(wit_string_t name) {
    WitInstance *self = allocate(1, sizeof(WitInstance));
    self->name = c_string(name);
    return self;
}

/* The option<own<instance>> for self: none (self freed) when instantiation failed. */
static void instance_option(WitInstance *self, int32_t (*new_handle)(int32_t), wit_option_int32_t *ret) {
    ret->is_some = self->instance != NULL;
    if (self->instance) {
        ret->val = new_handle((int32_t)(uintptr_t)self);
    } else {
        free(self->name);
        free(self);
        ret->val = 0;
    }
}

void fmi3_wit_instantiate_co_simulation(wit_string_t instance_name, wit_string_t instantiation_token,
                                        wit_string_t resource_path, bool visible, bool logging_on,
                                        bool event_mode_used, bool early_return_allowed,
                                        wit_list_uint32_t required_intermediate_variables,
                                        wit_option_int32_t *ret) {
    WitInstance *self = new_instance(instance_name);
    char *token = c_string(instantiation_token), *resources = c_string(resource_path);
    /* No intermediate-update callback is imported: the FMU never asks for one (it does not
       return early), whatever early_return_allowed says. */
    self->instance = fmi3InstantiateCoSimulation(
        self->name, token, resources, visible, logging_on, event_mode_used, early_return_allowed,
        required_intermediate_variables.ptr, required_intermediate_variables.len, self,
        forward_log_message, NULL);
    free(token);
    free(resources);
    instance_option(self, fmi3_wit_new_co_simulation_instance, ret);
}

void fmi3_wit_instantiate_model_exchange(wit_string_t instance_name, wit_string_t instantiation_token,
                                         wit_string_t resource_path, bool visible, bool logging_on,
                                         wit_option_int32_t *ret) {
    WitInstance *self = new_instance(instance_name);
    char *token = c_string(instantiation_token), *resources = c_string(resource_path);
    self->instance = fmi3InstantiateModelExchange(self->name, token, resources, visible, logging_on,
                                                  self, forward_log_message);
    free(token);
    free(resources);
    instance_option(self, fmi3_wit_new_model_exchange_instance, ret);
}

static void drop_instance(WitInstance *self) {
    fmi3FreeInstance(self->instance);
    free(self->name);
    free(self);
}

void fmi3_wit_drop_co_simulation_instance(WitInstance *self) { drop_instance(self); }
void fmi3_wit_drop_model_exchange_instance(WitInstance *self) { drop_instance(self); }

uint8_t fmi3_wit_set_debug_logging(WitInstance *self, bool logging_on, wit_list_string_t categories) {
    char **names = c_strings(categories);
    const fmi3Status status = fmi3SetDebugLogging(self->instance, logging_on, categories.len,
                                                  (const fmi3String *)names);
    free_c_strings(names, categories.len);
    return (uint8_t)status;
}

uint8_t fmi3_wit_enter_initialization_mode(WitInstance *self, wit_option_double_t tolerance,
                                           double start_time, wit_option_double_t stop_time) {
    return (uint8_t)fmi3EnterInitializationMode(self->instance, tolerance.is_some,
                                                tolerance.is_some ? tolerance.val : 0.0, start_time,
                                                stop_time.is_some, stop_time.is_some ? stop_time.val : 0.0);
}

/* The functions of an instance alone that return a status. */
#define STATUS_OF(wit_name, fmi3_name) \
    uint8_t wit_name(WitInstance *self) { return (uint8_t)fmi3_name(self->instance); }

STATUS_OF(fmi3_wit_exit_initialization_mode, fmi3ExitInitializationMode)
STATUS_OF(fmi3_wit_enter_event_mode, fmi3EnterEventMode)
STATUS_OF(fmi3_wit_terminate, fmi3Terminate)
STATUS_OF(fmi3_wit_reset, fmi3Reset)
STATUS_OF(fmi3_wit_enter_configuration_mode, fmi3EnterConfigurationMode)
STATUS_OF(fmi3_wit_exit_configuration_mode, fmi3ExitConfigurationMode)
STATUS_OF(fmi3_wit_evaluate_discrete_states, fmi3EvaluateDiscreteStates)
STATUS_OF(fmi3_wit_enter_step_mode, fmi3EnterStepMode)
STATUS_OF(fmi3_wit_enter_continuous_time_mode, fmi3EnterContinuousTimeMode)

void fmi3_wit_update_discrete_states(WitInstance *self, wit_result_discrete_states_info_uint8_t *ret) {
    fmi3Boolean needed = false, terminate = false, nominals = false, values = false, defined = false;
    fmi3Float64 next = 0.0;
    const fmi3Status status = fmi3UpdateDiscreteStates(self->instance, &needed, &terminate, &nominals,
                                                       &values, &defined, &next);
    ret->is_err = !succeeded(status);
    if (ret->is_err) {
        ret->val.err = (uint8_t)status;
        return;
    }
    ret->val.ok = (wit_discrete_states_info_t){needed, terminate, nominals, values, defined, next};
}

/* get-<type> and set-<type> of the types whose C array is the WIT list's own layout. */
#define GETTER(wit_name, fmi3_name, c_type, result_type)                                            \
    void wit_name(WitInstance *self, wit_list_uint32_t value_references, result_type *ret) {        \
        c_type *values = allocate(value_references.len, sizeof(c_type));                            \
        const fmi3Status status = fmi3_name(self->instance, value_references.ptr,                   \
                                            value_references.len, values, value_references.len);    \
        LIST_RESULT(ret, status, values, value_references.len);                                     \
    }
#define SETTER(wit_name, fmi3_name, list_type)                                                      \
    uint8_t wit_name(WitInstance *self, wit_list_uint32_t value_references, list_type values) {     \
        return (uint8_t)fmi3_name(self->instance, value_references.ptr, value_references.len,       \
                                  values.ptr, values.len);                                          \
    }

GETTER(fmi3_wit_get_float32, fmi3GetFloat32, float, wit_result_list_float_uint8_t)
GETTER(fmi3_wit_get_float64, fmi3GetFloat64, double, wit_result_list_double_uint8_t)
GETTER(fmi3_wit_get_int8, fmi3GetInt8, int8_t, wit_result_list_int8_uint8_t)
GETTER(fmi3_wit_get_int16, fmi3GetInt16, int16_t, wit_result_list_int16_uint8_t)
GETTER(fmi3_wit_get_int32, fmi3GetInt32, int32_t, wit_result_list_int32_uint8_t)
GETTER(fmi3_wit_get_int64, fmi3GetInt64, int64_t, wit_result_list_int64_uint8_t)
GETTER(fmi3_wit_get_uint8, fmi3GetUInt8, uint8_t, wit_result_list_uint8_uint8_t)
GETTER(fmi3_wit_get_uint16, fmi3GetUInt16, uint16_t, wit_result_list_uint16_uint8_t)
GETTER(fmi3_wit_get_uint32, fmi3GetUInt32, uint32_t, wit_result_list_uint32_uint8_t)
GETTER(fmi3_wit_get_uint64, fmi3GetUInt64, uint64_t, wit_result_list_uint64_uint8_t)
GETTER(fmi3_wit_get_boolean, fmi3GetBoolean, bool, wit_result_list_bool_uint8_t)
SETTER(fmi3_wit_set_float32, fmi3SetFloat32, wit_list_float_t)
SETTER(fmi3_wit_set_float64, fmi3SetFloat64, wit_list_double_t)
SETTER(fmi3_wit_set_int8, fmi3SetInt8, wit_list_int8_t)
SETTER(fmi3_wit_set_int16, fmi3SetInt16, wit_list_int16_t)
SETTER(fmi3_wit_set_int32, fmi3SetInt32, wit_list_int32_t)
SETTER(fmi3_wit_set_int64, fmi3SetInt64, wit_list_int64_t)
SETTER(fmi3_wit_set_uint8, fmi3SetUInt8, wit_list_uint8_t)
SETTER(fmi3_wit_set_uint16, fmi3SetUInt16, wit_list_uint16_t)
SETTER(fmi3_wit_set_uint32, fmi3SetUInt32, wit_list_uint32_t)
SETTER(fmi3_wit_set_uint64, fmi3SetUInt64, wit_list_uint64_t)
SETTER(fmi3_wit_set_boolean, fmi3SetBoolean, wit_list_bool_t)

/* fmi3GetClock takes no count of values: one per value reference. */
void fmi3_wit_get_clock(WitInstance *self, wit_list_uint32_t value_references, wit_result_list_bool_uint8_t *ret) {
    bool *values = allocate(value_references.len, sizeof(bool));
    const fmi3Status status = fmi3GetClock(self->instance, value_references.ptr, value_references.len, values);
    LIST_RESULT(ret, status, values, value_references.len);
}

uint8_t fmi3_wit_set_clock(WitInstance *self, wit_list_uint32_t value_references, wit_list_bool_t values) {
    if (values.len != value_references.len)
        return refuse(self, "set-clock: not as many values as value references");
    return (uint8_t)fmi3SetClock(self->instance, value_references.ptr, value_references.len, values.ptr);
}

void fmi3_wit_get_string(WitInstance *self, wit_list_uint32_t value_references, wit_result_list_string_uint8_t *ret) {
    const size_t count = value_references.len;
    fmi3String *values = allocate(count, sizeof(fmi3String));
    const fmi3Status status = fmi3GetString(self->instance, value_references.ptr, count, values, count);
    wit_string_t *copies = NULL;
    if (succeeded(status)) {
        copies = allocate(count, sizeof(wit_string_t));
        for (size_t i = 0; i < count; i++) copies[i] = wit_string(values[i]);
    }
    free(values); /* the instance owns the strings themselves */
    LIST_RESULT(ret, status, copies, count);
}

uint8_t fmi3_wit_set_string(WitInstance *self, wit_list_uint32_t value_references, wit_list_string_t values) {
    char **copies = c_strings(values);
    const fmi3Status status = fmi3SetString(self->instance, value_references.ptr, value_references.len,
                                            (const fmi3String *)copies, values.len);
    free_c_strings(copies, values.len);
    return (uint8_t)status;
}

void fmi3_wit_get_binary(WitInstance *self, wit_list_uint32_t value_references,
                         wit_result_list_list_uint8_uint8_t *ret) {
    const size_t count = value_references.len;
    size_t *sizes = allocate(count, sizeof(size_t));
    fmi3Binary *values = allocate(count, sizeof(fmi3Binary));
    const fmi3Status status = fmi3GetBinary(self->instance, value_references.ptr, count, sizes, values, count);
    wit_list_uint8_t *copies = NULL;
    if (succeeded(status)) {
        copies = allocate(count, sizeof(wit_list_uint8_t));
        for (size_t i = 0; i < count; i++) {
            copies[i] = (wit_list_uint8_t){allocate(sizes[i], 1), sizes[i]};
            if (sizes[i]) memcpy(copies[i].ptr, values[i], sizes[i]);
        }
    }
    free(sizes);
    free(values);
    LIST_RESULT(ret, status, copies, count);
}

uint8_t fmi3_wit_set_binary(WitInstance *self, wit_list_uint32_t value_references, wit_list_list_uint8_t values) {
    size_t *sizes = allocate(values.len, sizeof(size_t));
    fmi3Binary *pointers = allocate(values.len, sizeof(fmi3Binary));
    for (size_t i = 0; i < values.len; i++) {
        sizes[i] = values.ptr[i].len;
        pointers[i] = values.ptr[i].ptr;
    }
    const fmi3Status status = fmi3SetBinary(self->instance, value_references.ptr, value_references.len,
                                            sizes, pointers, values.len);
    free(sizes);
    free(pointers);
    return (uint8_t)status;
}

/* A size_t count as result<u64, status>. */
static void count_result(fmi3Status status, size_t count, wit_result_uint64_uint8_t *ret) {
    ret->is_err = !succeeded(status);
    if (ret->is_err) ret->val.err = (uint8_t)status;
    else ret->val.ok = count;
}

void fmi3_wit_get_number_of_variable_dependencies(WitInstance *self, uint32_t vr, wit_result_uint64_uint8_t *ret) {
    size_t count = 0;
    count_result(fmi3GetNumberOfVariableDependencies(self->instance, vr, &count), count, ret);
}

void fmi3_wit_get_variable_dependencies(WitInstance *self, uint32_t dependent,
                                        wit_result_list_variable_dependency_uint8_t *ret) {
    size_t count = 0;
    fmi3Status status = fmi3GetNumberOfVariableDependencies(self->instance, dependent, &count);
    wit_variable_dependency_t *rows = NULL;
    if (succeeded(status)) {
        size_t *dependent_elements = allocate(count, sizeof(size_t)), *independent_elements = allocate(count, sizeof(size_t));
        fmi3ValueReference *independents = allocate(count, sizeof(fmi3ValueReference));
        fmi3DependencyKind *kinds = allocate(count, sizeof(fmi3DependencyKind));
        status = fmi3GetVariableDependencies(self->instance, dependent, dependent_elements, independents,
                                             independent_elements, kinds, count);
        rows = allocate(count, sizeof(wit_variable_dependency_t));
        for (size_t i = 0; succeeded(status) && i < count; i++)
            rows[i] = (wit_variable_dependency_t){dependent, (uint32_t)dependent_elements[i], independents[i],
                                                  (uint32_t)independent_elements[i], (uint8_t)kinds[i]};
        free(dependent_elements);
        free(independent_elements);
        free(independents);
        free(kinds);
    }
    LIST_RESULT(ret, status, rows, count);
}

void fmi3_wit_get_fmu_state(WitInstance *self, wit_result_list_uint8_uint8_t *ret) {
    fmi3FMUState state = NULL;
    size_t size = 0;
    uint8_t *bytes = NULL;
    fmi3Status status = fmi3GetFMUState(self->instance, &state);
    if (succeeded(status)) status = fmi3SerializedFMUStateSize(self->instance, state, &size);
    if (succeeded(status)) {
        bytes = allocate(size, 1);
        status = fmi3SerializeFMUState(self->instance, state, bytes, size);
    }
    if (state) fmi3FreeFMUState(self->instance, &state);
    LIST_RESULT(ret, status, bytes, size);
}

uint8_t fmi3_wit_set_fmu_state(WitInstance *self, wit_list_uint8_t state) {
    fmi3FMUState restored = NULL;
    fmi3Status status = fmi3DeserializeFMUState(self->instance, state.ptr, state.len, &restored);
    if (succeeded(status)) {
        const fmi3Status set = fmi3SetFMUState(self->instance, restored);
        status = set > status ? set : status;
    }
    if (restored) fmi3FreeFMUState(self->instance, &restored);
    return (uint8_t)status;
}

void fmi3_wit_get_directional_derivative(WitInstance *self, wit_list_uint32_t unknowns, wit_list_uint32_t knowns,
                                         wit_list_double_t seed, wit_result_list_double_uint8_t *ret) {
    double *sensitivity = allocate(unknowns.len, sizeof(double));
    const fmi3Status status = fmi3GetDirectionalDerivative(self->instance, unknowns.ptr, unknowns.len, knowns.ptr,
                                                           knowns.len, seed.ptr, seed.len, sensitivity, unknowns.len);
    LIST_RESULT(ret, status, sensitivity, unknowns.len);
}

void fmi3_wit_get_adjoint_derivative(WitInstance *self, wit_list_uint32_t unknowns, wit_list_uint32_t knowns,
                                     wit_list_double_t seed, wit_result_list_double_uint8_t *ret) {
    double *sensitivity = allocate(knowns.len, sizeof(double));
    const fmi3Status status = fmi3GetAdjointDerivative(self->instance, unknowns.ptr, unknowns.len, knowns.ptr,
                                                       knowns.len, seed.ptr, seed.len, sensitivity, knowns.len);
    LIST_RESULT(ret, status, sensitivity, knowns.len);
}

void fmi3_wit_get_interval_decimal(WitInstance *self, wit_list_uint32_t value_references,
                                   wit_result_list_tuple_double_uint8_uint8_t *ret) {
    const size_t count = value_references.len;
    double *intervals = allocate(count, sizeof(double));
    fmi3IntervalQualifier *qualifiers = allocate(count, sizeof(fmi3IntervalQualifier));
    const fmi3Status status = fmi3GetIntervalDecimal(self->instance, value_references.ptr, count, intervals, qualifiers);
    wit_tuple_double_uint8_t *pairs = allocate(count, sizeof(wit_tuple_double_uint8_t));
    for (size_t i = 0; i < count; i++) pairs[i] = (wit_tuple_double_uint8_t){intervals[i], (uint8_t)qualifiers[i]};
    free(intervals);
    free(qualifiers);
    LIST_RESULT(ret, status, pairs, count);
}

void fmi3_wit_get_interval_fraction(WitInstance *self, wit_list_uint32_t value_references,
                                    wit_result_list_tuple_interval_fraction_uint8_uint8_t *ret) {
    const size_t count = value_references.len;
    uint64_t *counters = allocate(count, sizeof(uint64_t)), *resolutions = allocate(count, sizeof(uint64_t));
    fmi3IntervalQualifier *qualifiers = allocate(count, sizeof(fmi3IntervalQualifier));
    const fmi3Status status = fmi3GetIntervalFraction(self->instance, value_references.ptr, count, counters,
                                                      resolutions, qualifiers);
    wit_tuple_interval_fraction_uint8_t *pairs = allocate(count, sizeof(wit_tuple_interval_fraction_uint8_t));
    for (size_t i = 0; i < count; i++)
        pairs[i] = (wit_tuple_interval_fraction_uint8_t){{counters[i], resolutions[i]}, (uint8_t)qualifiers[i]};
    free(counters);
    free(resolutions);
    free(qualifiers);
    LIST_RESULT(ret, status, pairs, count);
}

void fmi3_wit_get_shift_decimal(WitInstance *self, wit_list_uint32_t value_references,
                                wit_result_list_double_uint8_t *ret) {
    double *shifts = allocate(value_references.len, sizeof(double));
    const fmi3Status status = fmi3GetShiftDecimal(self->instance, value_references.ptr, value_references.len, shifts);
    LIST_RESULT(ret, status, shifts, value_references.len);
}

void fmi3_wit_get_shift_fraction(WitInstance *self, wit_list_uint32_t value_references,
                                 wit_result_list_interval_fraction_uint8_t *ret) {
    const size_t count = value_references.len;
    uint64_t *counters = allocate(count, sizeof(uint64_t)), *resolutions = allocate(count, sizeof(uint64_t));
    const fmi3Status status = fmi3GetShiftFraction(self->instance, value_references.ptr, count, counters, resolutions);
    wit_interval_fraction_t *shifts = allocate(count, sizeof(wit_interval_fraction_t));
    for (size_t i = 0; i < count; i++) shifts[i] = (wit_interval_fraction_t){counters[i], resolutions[i]};
    free(counters);
    free(resolutions);
    LIST_RESULT(ret, status, shifts, count);
}

/* The C API takes as many values as value references, with no count of its own. */
#define SAME_COUNT(function, values, value_references)                            \
    if ((values).len != (value_references).len)                                   \
        return refuse(self, function ": not as many values as value references");

uint8_t fmi3_wit_set_interval_decimal(WitInstance *self, wit_list_uint32_t value_references, wit_list_double_t intervals) {
    SAME_COUNT("set-interval-decimal", intervals, value_references)
    return (uint8_t)fmi3SetIntervalDecimal(self->instance, value_references.ptr, value_references.len, intervals.ptr);
}

uint8_t fmi3_wit_set_shift_decimal(WitInstance *self, wit_list_uint32_t value_references, wit_list_double_t shifts) {
    SAME_COUNT("set-shift-decimal", shifts, value_references)
    return (uint8_t)fmi3SetShiftDecimal(self->instance, value_references.ptr, value_references.len, shifts.ptr);
}

/* The fractions' counters and resolutions as the C API's two arrays. */
static fmi3Status set_fractions(WitInstance *self, wit_list_uint32_t value_references, wit_list_interval_fraction_t fractions,
                                fmi3SetIntervalFractionTYPE *set) {
    uint64_t *counters = allocate(fractions.len, sizeof(uint64_t)), *resolutions = allocate(fractions.len, sizeof(uint64_t));
    for (size_t i = 0; i < fractions.len; i++) {
        counters[i] = fractions.ptr[i].counter;
        resolutions[i] = fractions.ptr[i].resolution;
    }
    const fmi3Status status = set(self->instance, value_references.ptr, value_references.len, counters, resolutions);
    free(counters);
    free(resolutions);
    return status;
}

uint8_t fmi3_wit_set_interval_fraction(WitInstance *self, wit_list_uint32_t value_references,
                                       wit_list_interval_fraction_t intervals) {
    SAME_COUNT("set-interval-fraction", intervals, value_references)
    return (uint8_t)set_fractions(self, value_references, intervals, fmi3SetIntervalFraction);
}

uint8_t fmi3_wit_set_shift_fraction(WitInstance *self, wit_list_uint32_t value_references,
                                    wit_list_interval_fraction_t shifts) {
    SAME_COUNT("set-shift-fraction", shifts, value_references)
    return (uint8_t)set_fractions(self, value_references, shifts, fmi3SetShiftFraction);
}

/* FMI 3.0 has no fmi3SetInputDerivatives (FMI 2.0's fmi2SetRealInputDerivatives went away), so
   there is no C function to call: the draft's WIT keeps it for a future mapping. */
uint8_t fmi3_wit_set_input_derivatives(WitInstance *self, wit_list_tuple_uint32_uint32_t requests, wit_list_double_t values) {
    (void)requests, (void)values;
    return refuse(self, "set-input-derivatives: not supported: FMI 3.0 has no fmi3SetInputDerivatives");
}

void fmi3_wit_get_output_derivatives(WitInstance *self, wit_list_tuple_uint32_uint32_t requests,
                                     wit_result_list_double_uint8_t *ret) {
    const size_t count = requests.len;
    fmi3ValueReference *value_references = allocate(count, sizeof(fmi3ValueReference));
    fmi3Int32 *orders = allocate(count, sizeof(fmi3Int32));
    for (size_t i = 0; i < count; i++) {
        value_references[i] = requests.ptr[i].f0;
        /* An order past fmi3Int32 is as wrong as any other the FMU refuses. */
        orders[i] = requests.ptr[i].f1 > INT32_MAX ? INT32_MAX : (fmi3Int32)requests.ptr[i].f1;
    }
    double *values = allocate(count, sizeof(double));
    const fmi3Status status = fmi3GetOutputDerivatives(self->instance, value_references, count, orders, values, count);
    free(value_references);
    free(orders);
    LIST_RESULT(ret, status, values, count);
}

void fmi3_wit_do_step(WitInstance *self, double current_communication_point, double communication_step_size,
                      bool no_set_fmu_state_prior_to_current_point, wit_result_do_step_result_uint8_t *ret) {
    fmi3Boolean event_handling_needed = false, terminate_simulation = false, early_return = false;
    fmi3Float64 last_successful_time = 0.0;
    const fmi3Status status = fmi3DoStep(self->instance, current_communication_point, communication_step_size,
                                         no_set_fmu_state_prior_to_current_point, &event_handling_needed,
                                         &terminate_simulation, &early_return, &last_successful_time);
    ret->is_err = !succeeded(status);
    if (ret->is_err) {
        ret->val.err = (uint8_t)status;
        return;
    }
    ret->val.ok = (wit_do_step_result_t){last_successful_time, event_handling_needed, terminate_simulation, early_return};
}

uint8_t fmi3_wit_set_time(WitInstance *self, double time) { return (uint8_t)fmi3SetTime(self->instance, time); }

uint8_t fmi3_wit_set_continuous_states(WitInstance *self, wit_list_double_t continuous_states) {
    return (uint8_t)fmi3SetContinuousStates(self->instance, continuous_states.ptr, continuous_states.len);
}

/* get-<vector>: as many values as the instance says it has (its number of states or event indicators). */
#define VECTOR_GETTER(wit_name, fmi3_name, fmi3_count)                                  \
    void wit_name(WitInstance *self, wit_result_list_double_uint8_t *ret) {             \
        size_t count = 0;                                                               \
        fmi3Status status = fmi3_count(self->instance, &count);                         \
        double *values = NULL;                                                          \
        if (succeeded(status)) {                                                        \
            values = allocate(count, sizeof(double));                                   \
            status = fmi3_name(self->instance, values, count);                          \
        }                                                                               \
        LIST_RESULT(ret, status, values, count);                                        \
    }

VECTOR_GETTER(fmi3_wit_get_continuous_state_derivatives, fmi3GetContinuousStateDerivatives,
              fmi3GetNumberOfContinuousStates)
VECTOR_GETTER(fmi3_wit_get_event_indicators, fmi3GetEventIndicators, fmi3GetNumberOfEventIndicators)
VECTOR_GETTER(fmi3_wit_get_continuous_states, fmi3GetContinuousStates, fmi3GetNumberOfContinuousStates)
VECTOR_GETTER(fmi3_wit_get_nominals_of_continuous_states, fmi3GetNominalsOfContinuousStates,
              fmi3GetNumberOfContinuousStates)

void fmi3_wit_get_number_of_event_indicators(WitInstance *self, wit_result_uint64_uint8_t *ret) {
    size_t count = 0;
    count_result(fmi3GetNumberOfEventIndicators(self->instance, &count), count, ret);
}

void fmi3_wit_get_number_of_continuous_states(WitInstance *self, wit_result_uint64_uint8_t *ret) {
    size_t count = 0;
    count_result(fmi3GetNumberOfContinuousStates(self->instance, &count), count, ret);
}

void fmi3_wit_completed_integrator_step(WitInstance *self, bool no_set_fmu_state_prior_to_current_point,
                                        wit_result_completed_step_result_uint8_t *ret) {
    fmi3Boolean enter_event_mode = false, terminate_simulation = false;
    const fmi3Status status = fmi3CompletedIntegratorStep(self->instance, no_set_fmu_state_prior_to_current_point,
                                                          &enter_event_mode, &terminate_simulation);
    ret->is_err = !succeeded(status);
    if (ret->is_err) ret->val.err = (uint8_t)status;
    else ret->val.ok = (wit_completed_step_result_t){enter_event_mode, terminate_simulation};
}
