/* The torque-driven pendulum:
       I_total * alpha = torque - mass*gravity*length*sin(theta) - damping*omega
       I_total = inertia + mass*length^2
   inertia is the head's own moment about its centre, moved to the pivot by the parallel-axis
   theorem. Everything here is SI. */

#include <math.h>
#include <stddef.h>

#include "model.h"

const char *model_invalid_parameters(const double values[N_VARIABLES]) {
    if (!(values[VR_MASS] > 0)) return "mass must be > 0";
    if (!(values[VR_LENGTH] >= 0)) return "length must be >= 0";
    if (!(values[VR_INERTIA] >= 0)) return "inertia must be >= 0";
    if (!(values[VR_DAMPING] >= 0)) return "damping must be >= 0";
    if (!isfinite(values[VR_GRAVITY])) return "gravity must be finite";
    const double inertia_total = values[VR_INERTIA] + values[VR_MASS] * values[VR_LENGTH] * values[VR_LENGTH];
    if (!(inertia_total > 0) || !isfinite(inertia_total))
        return "inertia + mass*length^2 (the inertia about the pivot) must be > 0 and finite";
    return NULL;
}

void model_coefficients(const double values[N_VARIABLES], ModelCoefficients *coefficients) {
    const double mass = values[VR_MASS], length = values[VR_LENGTH];
    coefficients->gravity_moment = mass * values[VR_GRAVITY] * length;
    coefficients->damping = values[VR_DAMPING];
    coefficients->inverse_inertia = 1.0 / (values[VR_INERTIA] + mass * length * length);
}

void model_get_states(const double values[N_VARIABLES], double x[N_STATES]) {
    x[0] = values[VR_THETA];
    x[1] = values[VR_OMEGA];
}

void model_set_states(double values[N_VARIABLES], const double x[N_STATES]) {
    values[VR_THETA] = x[0];
    values[VR_OMEGA] = x[1];
}

static double acceleration(const ModelCoefficients *k, double theta, double omega, double torque) {
    return (torque - k->gravity_moment * sin(theta) - k->damping * omega) * k->inverse_inertia;
}

void model_derivatives(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                       const InputDerivatives *inputs, double offset,
                       const double x[N_STATES], double dx[N_STATES]) {
    const double torque = input_at(values, inputs, VR_TORQUE, offset);
    dx[0] = x[1];
    dx[1] = acceleration(coefficients, x[0], x[1], torque);
}

void model_update_outputs(const ModelCoefficients *coefficients, double values[N_VARIABLES]) {
    values[VR_ALPHA] = acceleration(coefficients, values[VR_THETA], values[VR_OMEGA], values[VR_TORQUE]);
}

int model_output_derivative(const ModelCoefficients *k, const double values[N_VARIABLES],
                            const InputDerivatives *inputs, unsigned int vr, int order,
                            double *derivative) {
    const double theta = values[VR_THETA], omega = values[VR_OMEGA];
    const double alpha = acceleration(k, theta, omega, values[VR_TORQUE]);
    const double jerk = (inputs->first[VR_TORQUE] - k->gravity_moment * cos(theta) * omega
                         - k->damping * alpha) * k->inverse_inertia;
    const double snap = (inputs->second[VR_TORQUE]
                         + k->gravity_moment * (sin(theta) * omega * omega - cos(theta) * alpha)
                         - k->damping * jerk) * k->inverse_inertia;
    /* theta, omega, alpha are successive derivatives: the order-th derivative of the output
       at position p in that chain is the entry at p + order. */
    const double chain[5] = {theta, omega, alpha, jerk, snap};
    int position;
    switch (vr) {
        case VR_THETA: position = 0; break;
        case VR_OMEGA: position = 1; break;
        case VR_ALPHA: position = 2; break;
        default: return 0;
    }
    if (order < 1 || order > 2) return 0;
    *derivative = chain[position + order];
    return 1;
}

int model_partial_derivative(const ModelCoefficients *k, const double values[N_VARIABLES],
                             unsigned int unknown, unsigned int known, double *partial) {
    const int known_is_state = known == VR_THETA || known == VR_OMEGA;
    if (known != VR_TORQUE && !known_is_state) return 0;
    switch (unknown) {
        case VR_THETA:
        case VR_OMEGA:
            /* Outputs that are states depend only on themselves. */
            *partial = unknown == known ? 1.0 : 0.0;
            return 1;
        case VR_ALPHA:
            if (known == VR_TORQUE) *partial = k->inverse_inertia;
            else if (known == VR_THETA) *partial = -k->gravity_moment * cos(values[VR_THETA]) * k->inverse_inertia;
            else *partial = -k->damping * k->inverse_inertia;
            return 1;
        default:
            return 0;
    }
}
