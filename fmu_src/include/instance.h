#ifndef INSTANCE_H
#define INSTANCE_H

/* An FMU instance and the checks every call goes through, for either FMI standard: nothing here
   includes an FMI header or knows what the variables mean. The adapters (fmi2_functions.c,
   fmi3_functions.c) translate their standard's types to these and name the function that was
   called, so every message speaks the master's language. */

#include <stddef.h>
#include <stdio.h>
#include <stdint.h>

#include "model.h"
#include "record_file.h"

/* Same order and values as fmi2Status and fmi3Status, so an adapter converts by a cast. */
typedef enum {
    STATUS_OK,
    STATUS_WARNING,
    STATUS_DISCARD,
    STATUS_ERROR,
    STATUS_FATAL
} Status;

typedef enum {
    INTERFACE_MODEL_EXCHANGE,
    INTERFACE_CO_SIMULATION
} InterfaceType;

/* The machine states of both standards, as bits so that each function's allowed states are a
   mask. STEP_COMPLETE is FMI 3.0's step mode and STEP_FAILED its step discarded. */
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

/* Beside the states, the mask of a function that belongs to one interface says which: the two
   interfaces share the states instantiated, initialization mode and terminated, so the states
   alone would let the other interface's instances call it there. */
#define CO_SIMULATION_ONLY (1 << 7)
#define MODEL_EXCHANGE_ONLY (1 << 8)

#define DEFAULT_TOLERANCE 1e-10
/* Internal steps one communication step may try before it gives up with a discard. */
#define MAX_INTERNAL_STEPS 100000L
#define MAX_INSTANCE_NAME 128
/* FMU states one instance holds at most: each call that takes a state looks it up in the
   instance's list, so a master that never frees its states would otherwise slow every such call
   without end. */
#define MAX_FMU_STATES 10000

/* The master's logger as an adapter hands it over: its function, cast to a generic function
   pointer, and forward, the adapter's function that casts it back and calls it. */
typedef void (*AnyFunction)(void);
typedef void (*LogForwarder)(AnyFunction master_logger, void *environment, const char *instance_name,
                             Status status, const char *category, const char *message);
typedef struct {
    LogForwarder forward;
    AnyFunction master_logger;
    void *environment;
} Logger;

/* Everything that says where an instance stands. An FMU state is a copy of it and a serialized
   FMU state is its bytes, so a rollback restores results bit for bit. */
typedef struct {
    int64_t machine_state;               /* a MachineState; 64 bits so the struct has no padding */
    double time;
    double last_successful_time;
    double tolerance;
    double step_size;                    /* the internal step carried between communication steps */
    double values[N_VARIABLES];          /* indexed by value reference */
    InputDerivatives inputs;             /* the inputs' derivatives at `time` */
} InstanceData;

typedef enum {
    LOG_STATUS_WARNING = 1 << 0,
    LOG_STATUS_DISCARD = 1 << 1,
    LOG_STATUS_ERROR = 1 << 2,
    LOG_ALL = 1 << 3,
    LOG_CALLS = 1 << 4                   /* the call record: one line per call received */
} LogCategory;
/* Beside the categories: the call record goes to the file callRecordFile names. */
#define RECORD_TO_FILE (1 << 5)
#define RECORD_BITS (LOG_CALLS | RECORD_TO_FILE)
/* The longest callRecordFile, with its terminating zero. */
#define MAX_RECORD_FILE_NAME 1024
/* A record line's arguments: the longest is fmi*SetString's, the record file's name escaped; a
   call that sets every variable at round-trip precision fits too. */
#define RECORD_ARGUMENTS_SIZE (ESCAPED_SIZE(MAX_RECORD_FILE_NAME) + 16)
/* A record line: its arguments, the instance name escaped, the function, times and status. */
#define RECORD_LINE_SIZE (RECORD_ARGUMENTS_SIZE + ESCAPED_SIZE(MAX_INSTANCE_NAME) + 256)

typedef struct {
    InstanceData data;
    /* Derived from data: recomputed whenever data changes outside a step. */
    ModelCoefficients coefficients;
    int outputs_stale;
    int ignored_orders_logged;           /* the one message about input derivatives of order > 2 */
    InterfaceType type;                  /* fixed at instantiation */
    Logger logger;
    int log_categories;                  /* LogCategory bits switched on by the master, and RECORD_TO_FILE */
    /* The call record's file (the String parameter callRecordFile; not part of an FMU state). */
    char record_file_name[MAX_RECORD_FILE_NAME];
    FILE *record_file;
    char name[MAX_INSTANCE_NAME];
    /* The FMU states this instance handed out and has not freed (fmu_state.c): a state the master
       passes back is looked up here by its address before anything in it is read. */
    struct StoredState *states;
    size_t n_states;
} Instance;

/* Every function below takes `function`, the name of the FMI function the master called, for
   its messages. */

/* NULL (after logging why, when there is a logger) unless the arguments make an instance. */
Instance *instance_create(const char *function, const char *name, const char *token_argument,
                          const char *token, InterfaceType type, const Logger *logger, int logging_on);
/* Logs why an instantiation is refused (when there is a logger) as instance_error does, and
   returns NULL: for refusals before there is an instance. */
Instance *instance_refuse(const char *function, const char *name, const Logger *logger,
                          const char *format, ...);
void instance_free(Instance *instance);
void instance_reset(Instance *instance);

/* Logs through the master's logger: status messages always, debug messages (category LOG_ALL)
   only when the master switched them on. */
void instance_log(const Instance *instance, Status status, LogCategory category,
                  const char *format, ...);
Status instance_error(const Instance *instance, const char *function, const char *format, ...);

/* The call record: one line per call the instance receives, under category logCalls, so that a
   user can show what a master did to the FMU. Each line starts with CALL_RECORD_MARKER and names
   the instance inside the message, because masters print messages in formats of their own and
   some drop the instance name; pendulum_fmu/judging/_call_record.py reads the lines back. The
   adapters test instance_recording before they format anything, so that a step costs one test
   when it is off. */
#define CALL_RECORD_MARKER "[pendulum-calls]"
/* For the out-of-line recording paths of the functions a master calls every step. */
#if defined(_MSC_VER)
#define NOINLINE __declspec(noinline)
#else
#define NOINLINE __attribute__((noinline))
#endif
static inline int instance_recording(const Instance *instance) {
    return instance->log_categories & RECORD_BITS;
}
/* For the adapters' entry points, whose locals are `instance` and `function`: the time before
   the call, kept for its line, and the line itself, formatted only when the record is on. */
#define KEEP_TIME const double time_before = instance->data.time;
#define RECORD(status, ...)                                                            \
    if (instance_recording(instance))                                                  \
        instance_record_call(instance, function, time_before, (status), __VA_ARGS__);
#define RECORD_VALUES(status, vr, order, n, value)                                     \
    if (instance_recording(instance))                                                  \
        instance_record_values(instance, function, time_before, (status), (vr), (order), (n), \
                               (value));
/* The functions a master calls every step ask the record first and, when it is on, go out of
   line to a function that calls the entry point again with the record switched off for the call
   (this macro), then records it. So with the record off an entry point keeps its path as it was
   (the core's function inlined into it, its only caller; a tail call) and a step pays one test. */
#define WITHOUT_RECORD(status_type, call)                                              \
    const double time_before = instance->data.time;                                    \
    const int recording = instance->log_categories & RECORD_BITS;                      \
    instance->log_categories &= ~RECORD_BITS;                                          \
    const status_type status = (call);                                                 \
    instance->log_categories |= recording;
/* `format` describes the arguments; the line adds the FMU's time before and after the call and
   the status it returned. */
void instance_record_call(const Instance *instance, const char *function, double time_before,
                          Status status, const char *format, ...);
/* The arguments are values by variable name (vr given: "torque=20"), input derivatives by name
   and order (order given too: "der(torque,1)=5"), or a state vector (vr NULL: "x[0]=0.1"). */
/* The String parameters (callRecordFile): set by value reference, each value a file name that
   is opened for appending at once where record_file_open allows (else a warning, and no record
   file); get returns the name as set. */
Status instance_set_string(Instance *instance, const char *function, const unsigned int vr[], size_t n,
                           const char *const value[]);
Status instance_get_string(Instance *instance, const char *function, const unsigned int vr[], size_t n,
                           const char *value[]);
void instance_record_values(const Instance *instance, const char *function, double time_before,
                            Status status, const unsigned int vr[], const int order[], size_t n,
                            const double value[]);

/* Logs why mask does not allow the call (the function is the other interface's, or the machine
   state is not in it); returns 0. */
int instance_illegal_call(const Instance *instance, int mask, const char *function);

/* 1 when the instance's machine state is in mask and the mask does not keep the function to the
   other interface, else logs an illegal call. Inline, so that each entry point's constant mask
   folds the check to a test or two: the interface is asked only where the mask allows a state
   both interfaces share. */
static inline int instance_state_allows(const Instance *instance, int mask, const char *function) {
    const int shared_states = STATE_INSTANTIATED | STATE_INITIALIZATION_MODE | STATE_TERMINATED;
    const int interface_only = mask & (CO_SIMULATION_ONLY | MODEL_EXCHANGE_ONLY);
    if ((instance->data.machine_state & mask)
        && (!(interface_only && (mask & shared_states))
            || interface_only == (instance->type == INTERFACE_CO_SIMULATION ? CO_SIMULATION_ONLY
                                                                            : MODEL_EXCHANGE_ONLY)))
        return 1;
    return instance_illegal_call(instance, mask, function);
}
int instance_null_argument(const Instance *instance, const char *function, const char *argument,
                           const void *pointer);
/* 1 when the value references are all variables of this FMU, else logs which is not. */
int instance_known_references(const Instance *instance, const char *function,
                              const unsigned int vr[], size_t nvr);

Status instance_set_debug_logging(Instance *instance, const char *function, int logging_on,
                                  size_t n_categories, const char *const categories[]);
Status instance_setup_experiment(Instance *instance, const char *function, int tolerance_defined,
                                 double tolerance, double start_time);
Status instance_exit_initialization(Instance *instance, const char *function);
Status instance_get_real(Instance *instance, const char *function, const unsigned int vr[],
                         size_t nvr, double value[]);
Status instance_set_real(Instance *instance, const char *function, const unsigned int vr[],
                         size_t nvr, const double value[]);
/* Orders 1 and 2 shape the inputs over the next steps; higher orders are ignored (one message
   per instance). */
Status instance_set_input_derivatives(Instance *instance, const char *function,
                                      const unsigned int vr[], size_t nvr, const int order[],
                                      const double value[]);
Status instance_get_output_derivatives(Instance *instance, const char *function,
                                       const unsigned int vr[], size_t nvr, const int order[],
                                       double value[]);
/* unknown_delta = J * known_delta, J[i][j] = d unknown[i] / d known[j]. */
Status instance_directional_derivative(Instance *instance, const char *function,
                                       const unsigned int unknown[], size_t n_unknown,
                                       const unsigned int known[], size_t n_known,
                                       const double known_delta[], double unknown_delta[]);
/* known_sensitivity = J^T * unknown_seed, the same J. */
Status instance_adjoint_derivative(Instance *instance, const char *function,
                                   const unsigned int unknown[], size_t n_unknown,
                                   const unsigned int known[], size_t n_known,
                                   const double unknown_seed[], double known_sensitivity[]);
Status instance_do_step(Instance *instance, const char *function, double communication_point,
                        double communication_step);

/* Model exchange: the continuous states and their derivatives. */
Status instance_set_time(Instance *instance, const char *function, double time);
Status instance_set_states(Instance *instance, const char *function, const double x[], size_t nx);
Status instance_get_states(Instance *instance, const char *function, double x[], size_t nx);
Status instance_get_derivatives(Instance *instance, const char *function, double dx[], size_t nx);
Status instance_get_nominals(Instance *instance, const char *function, double nominals[], size_t nx);

/* FMU states (fmu_state.c): opaque to the adapters, which pass their fmi*FMUstate through. A
   state not handed out by this instance (freed, another instance's, or no state at all) is
   refused with an error, and the instance goes on. */
Status instance_get_state(Instance *instance, const char *function, void **state);
Status instance_set_state(Instance *instance, const char *function, const void *state);
Status instance_free_state(Instance *instance, const char *function, void **state);
Status instance_serialized_state_size(Instance *instance, const char *function, const void *state,
                                      size_t *size);
Status instance_serialize_state(Instance *instance, const char *function, const void *state,
                                unsigned char bytes[], size_t size);
Status instance_deserialize_state(Instance *instance, const char *function,
                                  const unsigned char bytes[], size_t size, void **state);
/* Frees the states the master did not free, when the instance goes. */
void instance_free_states(Instance *instance);
/* Recomputes what is derived from data after data was replaced wholesale. */
void instance_data_changed(Instance *instance);

#endif
