#ifndef INSTANCE_H
#define INSTANCE_H

/* An FMU instance and the checks every FMI call goes through. Nothing here knows what the
   variables mean: that is model.c's business. */

#include <stdint.h>

#include "fmi2Functions.h"
#include "model.h"

/* The FMI 2.0 states, as bits so that each function's allowed states are a mask. Co-simulation
   instances never reach the model-exchange states and vice versa, so the masks also keep each
   interface's functions to its own instances. */
typedef enum {
    STATE_INSTANTIATED = 1 << 0,
    STATE_INITIALIZATION_MODE = 1 << 1,
    STATE_STEP_COMPLETE = 1 << 2,
    STATE_STEP_FAILED = 1 << 3,
    STATE_TERMINATED = 1 << 4,
    STATE_EVENT_MODE = 1 << 5,
    STATE_CONTINUOUS_TIME_MODE = 1 << 6
} MachineState;

#define CO_SIMULATION_STATES (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE | STATE_STEP_COMPLETE \
                              | STATE_STEP_FAILED | STATE_TERMINATED)
#define MODEL_EXCHANGE_STATES (STATE_INSTANTIATED | STATE_INITIALIZATION_MODE | STATE_EVENT_MODE \
                               | STATE_CONTINUOUS_TIME_MODE | STATE_TERMINATED)

#define DEFAULT_TOLERANCE 1e-10
/* Internal steps one fmi2DoStep may try before it gives up with fmi2Discard. */
#define MAX_INTERNAL_STEPS 100000L
#define MAX_INSTANCE_NAME 128

/* Everything that says where an instance stands. An FMU state is a copy of it and a serialized
   FMU state is its bytes, so a rollback restores results bit for bit. */
typedef struct {
    int64_t machine_state;               /* a MachineState; 64 bits so the struct has no padding */
    double time;
    double last_successful_time;
    double tolerance;
    double step_size;                    /* the internal step carried between communication steps */
    double values[N_VARIABLES];          /* indexed by value reference */
    double input_rates[N_VARIABLES];     /* first derivatives from fmi2SetRealInputDerivatives */
} InstanceData;

typedef enum {
    LOG_STATUS_WARNING = 1 << 0,
    LOG_STATUS_DISCARD = 1 << 1,
    LOG_STATUS_ERROR = 1 << 2,
    LOG_ALL = 1 << 3
} LogCategory;

typedef struct {
    InstanceData data;
    /* Derived from data: recomputed whenever data changes outside a step. */
    ModelCoefficients coefficients;
    int outputs_stale;
    fmi2Type type;                       /* co-simulation or model exchange, fixed at instantiation */
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment environment;
    int log_categories;                  /* LogCategory bits switched on by the master */
    char name[MAX_INSTANCE_NAME];
} Instance;

Instance *instance_create(fmi2String name, fmi2String guid, fmi2Type type,
                          const fmi2CallbackFunctions *callbacks, fmi2Boolean logging_on);
void instance_free(Instance *instance);
void instance_reset(Instance *instance);

/* Logs through the master's logger: status messages always, debug messages (category LOG_ALL)
   only when the master switched them on. */
void instance_log(const Instance *instance, fmi2Status status, LogCategory category,
                  const char *format, ...);
fmi2Status instance_error(const Instance *instance, const char *function, const char *format, ...);

/* 1 when the instance's machine state is in mask, else logs an illegal call sequence. */
int instance_state_allows(const Instance *instance, int mask, const char *function);
int instance_null_argument(const Instance *instance, const char *function, const char *argument,
                           const void *pointer);

fmi2Status instance_set_debug_logging(Instance *instance, fmi2Boolean logging_on,
                                      size_t n_categories, const fmi2String categories[]);
fmi2Status instance_setup_experiment(Instance *instance, fmi2Boolean tolerance_defined,
                                     fmi2Real tolerance, fmi2Real start_time);
fmi2Status instance_exit_initialization(Instance *instance);
fmi2Status instance_get_real(Instance *instance, const fmi2ValueReference vr[], size_t nvr,
                             fmi2Real value[]);
fmi2Status instance_set_real(Instance *instance, const fmi2ValueReference vr[], size_t nvr,
                             const fmi2Real value[]);
fmi2Status instance_set_input_derivatives(Instance *instance, const fmi2ValueReference vr[],
                                          size_t nvr, const fmi2Integer order[],
                                          const fmi2Real value[]);
fmi2Status instance_get_output_derivatives(Instance *instance, const fmi2ValueReference vr[],
                                           size_t nvr, const fmi2Integer order[], fmi2Real value[]);
fmi2Status instance_directional_derivative(Instance *instance, const fmi2ValueReference unknown[],
                                           size_t n_unknown, const fmi2ValueReference known[],
                                           size_t n_known, const fmi2Real known_delta[],
                                           fmi2Real unknown_delta[]);
fmi2Status instance_do_step(Instance *instance, fmi2Real communication_point,
                            fmi2Real communication_step);

/* Model exchange: the continuous states and their derivatives. */
fmi2Status instance_set_time(Instance *instance, fmi2Real time);
fmi2Status instance_set_states(Instance *instance, const fmi2Real x[], size_t nx);
fmi2Status instance_get_states(Instance *instance, fmi2Real x[], size_t nx);
fmi2Status instance_get_derivatives(Instance *instance, fmi2Real dx[], size_t nx);

/* FMU states (fmu_state.c). */
fmi2Status instance_get_state(Instance *instance, fmi2FMUstate *state);
fmi2Status instance_set_state(Instance *instance, fmi2FMUstate state);
fmi2Status instance_free_state(Instance *instance, fmi2FMUstate *state);
fmi2Status instance_serialized_state_size(Instance *instance, fmi2FMUstate state, size_t *size);
fmi2Status instance_serialize_state(Instance *instance, fmi2FMUstate state, fmi2Byte bytes[],
                                    size_t size);
fmi2Status instance_deserialize_state(Instance *instance, const fmi2Byte bytes[], size_t size,
                                      fmi2FMUstate *state);
/* Recomputes what is derived from data after data was replaced wholesale. */
void instance_data_changed(Instance *instance);

#endif
