/* A PID controller for the pendulum: it reads the angle and rate and returns the torque
       torque = kp*(setpoint - theta) + ki*integral(setpoint - theta) - kd*omega
   The rate comes from the pendulum itself, so the derivative term needs no differentiation;
   the integral term removes the offset gravity would leave. */

#include <math.h>
#include <stddef.h>

#include "model.h"

const char *model_invalid_parameters(const double values[N_VARIABLES]) {
    if (!(values[VR_KP] >= 0) || !(values[VR_KI] >= 0) || !(values[VR_KD] >= 0))
        return "the gains kp, ki, kd must be >= 0";
    if (!isfinite(values[VR_KP] + values[VR_KI] + values[VR_KD] + values[VR_SETPOINT]))
        return "the gains and the set-point must be finite";
    return NULL;
}

void model_coefficients(const double values[N_VARIABLES], ModelCoefficients *coefficients) {
    coefficients->setpoint = values[VR_SETPOINT];
    coefficients->proportional_gain = values[VR_KP];
    coefficients->integral_gain = values[VR_KI];
    coefficients->derivative_gain = values[VR_KD];
}

void model_get_states(const double values[N_VARIABLES], double x[N_STATES]) {
    x[0] = values[VR_ERROR_INTEGRAL];
}

void model_set_states(double values[N_VARIABLES], const double x[N_STATES]) {
    values[VR_ERROR_INTEGRAL] = x[0];
}

void model_derivatives(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                       const InputDerivatives *inputs, double offset,
                       const double x[N_STATES], double dx[N_STATES]) {
    (void)x;
    dx[0] = coefficients->setpoint - input_at(values, inputs, VR_THETA, offset);
}

int model_taylor_series(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                        const InputDerivatives *inputs, double offset, double h,
                        double series[TAYLOR_ORDER + 1][N_STATES]) {
    /* No series: the integrator steps the controller with DOPRI5. */
    (void)coefficients, (void)values, (void)inputs, (void)offset, (void)h, (void)series;
    return 0;
}

void model_update_outputs(const ModelCoefficients *k, double values[N_VARIABLES]) {
    values[VR_TORQUE] = k->proportional_gain * (k->setpoint - values[VR_THETA])
                        + k->integral_gain * values[VR_ERROR_INTEGRAL]
                        - k->derivative_gain * values[VR_OMEGA];
}

int model_output_derivative(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                            const InputDerivatives *inputs, unsigned int vr, int order,
                            double *derivative) {
    (void)coefficients, (void)values, (void)inputs, (void)vr, (void)order, (void)derivative;
    return 0;
}

int model_partial_derivative(const ModelCoefficients *k, const double values[N_VARIABLES],
                             unsigned int unknown, unsigned int known, double *partial) {
    (void)values;
    if (unknown != VR_TORQUE) return 0;
    switch (known) {
        case VR_THETA: *partial = -k->proportional_gain; return 1;
        case VR_OMEGA: *partial = -k->derivative_gain; return 1;
        default: return 0;
    }
}
