/* A generic FMI 2.0 co-simulation loop: one call runs a whole schedule through the FMU's own
   exported fmi2SetReal, fmi2SetRealInputDerivatives, fmi2GetReal and fmi2DoStep.

   Plain C99, not a CPython module: Python loads it with ctypes and passes the addresses of the
   functions of the FMU library fmpy already loaded, the instance, and numpy buffers. Nothing is
   allocated here, so the cost of a step is the FMU's own work plus four indirect calls.

   The call sequence is the one of the Python loop in pendulum_fmu/simulate.py (the readable
   reference), so the two give bit-identical results: per step k, set the inputs, set their
   first derivatives (when rates are given), read the outputs, step from time[k] by
   time[k+1] - time[k]; after the last step read the inputs and the outputs once more. */

#include <stddef.h>

#include "fmi2FunctionTypes.h"

#if defined(_WIN32)
#define CS_LOOP_EXPORT __declspec(dllexport)
#else
#define CS_LOOP_EXPORT __attribute__((visibility("default")))
#endif

/* Which call failed, as reported through *failed_call. */
enum { CALL_SET_REAL = 0, CALL_SET_RATE = 1, CALL_GET_REAL = 2, CALL_DO_STEP = 3,
       CALL_GET_INPUTS_AT_END = 4, CALL_GET_OUTPUTS_AT_END = 5 };

/* Runs n_steps communication steps.

   time[0..n_steps]                  communication points
   inputs[k*n_inputs + i]            input i over step k (the value at the step's start)
   input_rates[k*n_inputs + i]       its derivative of order input_orders[i] (1 for a ramp) over
                                     step k, or input_rates == NULL to hold the inputs
                                     (fmi2SetRealInputDerivatives is not called)
   outputs[k*n_outputs + j]          output j at point k (k = 0..n_steps), read after the
                                     inputs of step k were set
   final_inputs[i]                   the inputs read back after the last step (may be NULL)

   Returns fmi2OK or fmi2Warning when every call succeeded (a warning is the worst status seen),
   else the failing call's status, with *failed_step = k (n_steps for the reads at the end) and
   *failed_call one of the CALL_ values; the outputs before the failure are filled in. */
CS_LOOP_EXPORT int cs_loop_run(
    fmi2SetRealTYPE *set_real, fmi2SetRealInputDerivativesTYPE *set_real_input_derivatives,
    fmi2GetRealTYPE *get_real, fmi2DoStepTYPE *do_step, fmi2Component component,
    const fmi2ValueReference *input_references, size_t n_inputs,
    const fmi2ValueReference *output_references, size_t n_outputs,
    size_t n_steps, const double *time, const double *inputs,
    const fmi2Integer *input_orders, const double *input_rates,
    double *outputs, double *final_inputs,
    size_t *failed_step, int *failed_call)
{
    fmi2Status worst = fmi2OK, status;
    size_t k;

#define CHECK(call_expression, which)                                                   \
    do {                                                                                \
        status = (call_expression);                                                     \
        if (status > fmi2Warning) { *failed_step = k; *failed_call = (which); return (int)status; } \
        if (status > worst) worst = status;                                             \
    } while (0)

    for (k = 0; k < n_steps; k++) {
        if (n_inputs) {
            CHECK(set_real(component, input_references, n_inputs, inputs + k * n_inputs),
                  CALL_SET_REAL);
            if (input_rates != NULL)
                CHECK(set_real_input_derivatives(component, input_references, n_inputs,
                                                 input_orders, input_rates + k * n_inputs),
                      CALL_SET_RATE);
        }
        CHECK(get_real(component, output_references, n_outputs, outputs + k * n_outputs),
              CALL_GET_REAL);
        CHECK(do_step(component, time[k], time[k + 1] - time[k], fmi2True), CALL_DO_STEP);
    }
    if (final_inputs != NULL && n_inputs)
        CHECK(get_real(component, input_references, n_inputs, final_inputs),
              CALL_GET_INPUTS_AT_END);
    CHECK(get_real(component, output_references, n_outputs, outputs + k * n_outputs),
          CALL_GET_OUTPUTS_AT_END);
#undef CHECK
    return (int)worst;
}
