/* Integration error's candidates (pendulum_fmu/judging/_euler.py, euler_steps) in C: the
   equation of motion stepped once per communication step, holding each step's start torque, by
   explicit or semi-implicit Euler, a window of steps in one call.

   It is the Python loop transcribed, the same operations in the same order, with libm's sin as
   Python's math.sin calls it, built without FMA contraction (cmake/flags.cmake), so that the two
   give the same numbers bit for bit (tests/test_euler.py). In Python a step costs some 0.5 us,
   a judge's largest cost after the oracle's at a torque that changes every step. It is compiled
   into the native loop's library (_cs_loop, CMakeLists.txt) only to travel in the same file of
   every wheel, shares no code with it, and allocates nothing. */

#include <math.h>
#include <stddef.h>

#if defined(_WIN32)
#define EULER_EXPORT __declspec(dllexport)
#else
#define EULER_EXPORT __attribute__((visibility("default")))
#endif

/* Changes whenever cs_loop_euler_steps's arguments do (_euler.py checks it). */
EULER_EXPORT int cs_loop_euler_interface(void) { return 1; }

/* count steps from state (theta, omega; the state reached is written back): step k of length
   step_sizes[k] holds torques[k]. thetas and omegas (count + 1 each) get the state at each
   step's start and, last, at the end. model: mass*gravity*length, damping, 1/total inertia. */
EULER_EXPORT void cs_loop_euler_steps(double *state, const double *step_sizes, const double *torques, size_t count,
                                      const double *model, int semi_implicit, double *thetas, double *omegas)
{
    const double gravity_moment = model[0], damping = model[1], inverse_inertia = model[2];
    double theta = state[0], omega = state[1];
    size_t k;
    for (k = 0; k < count; k++) {
        const double h = step_sizes[k];
        const double alpha = (torques[k] - gravity_moment * sin(theta) - damping * omega) * inverse_inertia;
        thetas[k] = theta;
        omegas[k] = omega;
        if (semi_implicit) {
            omega = omega + h * alpha;
            theta = theta + h * omega;
        } else {
            const double moved = theta + h * omega;
            omega = omega + h * alpha;
            theta = moved;
        }
    }
    thetas[count] = theta;
    omegas[count] = omega;
    state[0] = theta;
    state[1] = omega;
}
