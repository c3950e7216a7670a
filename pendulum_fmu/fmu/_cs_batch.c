/* A batch of FMI 2.0 co-simulation instances of one FMU, each advanced by one communication step
   (or restarted) in one call, over a pool of threads: what a vectorised environment needs.

   Plain C99, compiled into the native loop's library (_cs_loop.c, whose CsFunctions it shares) and
   loaded with ctypes by pendulum_fmu/fmu/_batch.py. The pool's threads are made once (a call
   allocates nothing and makes no thread); each call splits the instances into one contiguous slice
   per thread, the caller's thread taking the first, and returns when every slice is done. The
   instances are independent FMI components, so no two threads touch the same one.

   Per instance i, by modes[i], in the order of the Python loop in _batch.py (the readable
   reference, which gives the same numbers bit for bit):
     BATCH_STEP     fmi2SetReal(inputs of row i),
                    fmi2DoStep(start_time + steps[i] * step_size, step_size); steps[i] += 1
     BATCH_RESTART  fmi2Reset, fmi2SetupExperiment(tolerance, start_time),
                    fmi2EnterInitializationMode, fmi2SetReal(start values of row i),
                    fmi2ExitInitializationMode; steps[i] = 0
     BATCH_HOLD     nothing
   then fmi2GetReal(outputs of row i). The communication points are start_time + k * step_size, as
   every other loop of the package has them (not a running sum, whose rounding the FMU's steps would
   see), so that an instance's steps are those of a schedule's run bit for bit. */

#if !defined(_WIN32)
#define _POSIX_C_SOURCE 200809L
#endif

#include <stdint.h>
#include <stdlib.h>

#include "_cs_loop.h"

#if defined(_WIN32)
#include <windows.h>
typedef SRWLOCK Lock;
typedef CONDITION_VARIABLE Condition;
typedef HANDLE Thread;
static void lock_init(Lock *lock) { InitializeSRWLock(lock); }
static void lock_destroy(Lock *lock) { (void)lock; }
static void lock(Lock *lock) { AcquireSRWLockExclusive(lock); }
static void unlock(Lock *lock) { ReleaseSRWLockExclusive(lock); }
static void condition_init(Condition *condition) { InitializeConditionVariable(condition); }
static void condition_destroy(Condition *condition) { (void)condition; }
static void condition_wait(Condition *condition, Lock *lock) {
    SleepConditionVariableSRW(condition, lock, INFINITE, 0);
}
static void condition_broadcast(Condition *condition) { WakeAllConditionVariable(condition); }
#else
#include <pthread.h>
typedef pthread_mutex_t Lock;
typedef pthread_cond_t Condition;
typedef pthread_t Thread;
static void lock_init(Lock *lock) { pthread_mutex_init(lock, NULL); }
static void lock_destroy(Lock *lock) { pthread_mutex_destroy(lock); }
static void lock(Lock *lock) { pthread_mutex_lock(lock); }
static void unlock(Lock *lock) { pthread_mutex_unlock(lock); }
static void condition_init(Condition *condition) { pthread_cond_init(condition, NULL); }
static void condition_destroy(Condition *condition) { pthread_cond_destroy(condition); }
static void condition_wait(Condition *condition, Lock *lock) { pthread_cond_wait(condition, lock); }
static void condition_broadcast(Condition *condition) { pthread_cond_broadcast(condition); }
#endif

enum { BATCH_STEP = 0, BATCH_RESTART = 1, BATCH_HOLD = 2 };

/* One call's instances and buffers, laid out as _batch.py's ctypes Structure mirrors it. Every
   array has a row per instance; statuses[i] is the worst status of instance i's calls, and
   failed_calls[i] the CALL_ value of the call that failed (when statuses[i] > fmi2Warning). */
typedef struct {
    const CsFunctions *fmi;
    fmi2Component *components;
    size_t n_instances;
    const fmi2ValueReference *start_references;
    size_t n_start;
    const double *start_values;     /* [n_instances][n_start] */
    const unsigned char *modes;     /* [n_instances]: BATCH_STEP, BATCH_RESTART or BATCH_HOLD */
    const double *tolerance;        /* NULL: the FMU's own */
    double start_time;
    const fmi2ValueReference *input_references;
    size_t n_inputs;
    const double *inputs;           /* [n_instances][n_inputs] */
    const fmi2ValueReference *output_references;
    size_t n_outputs;
    double *outputs;                /* [n_instances][n_outputs] */
    uint64_t *steps;                /* [n_instances]: the steps since the last restart */
    double step_size;
    int *statuses;                  /* [n_instances] */
    int *failed_calls;              /* [n_instances] */
} CsBatch;

static int advance(const CsBatch *b, size_t i) {
    const CsFunctions *fmi = b->fmi;
    fmi2Component component = b->components[i];
    fmi2Status worst = fmi2OK, status;

#define CHECK(call_expression, which)                                                  \
    do {                                                                               \
        status = (call_expression);                                                    \
        if (status > fmi2Warning) { b->failed_calls[i] = (which); return (int)status; } \
        if (status > worst) worst = status;                                            \
    } while (0)

    if (b->modes[i] == BATCH_RESTART) {
        CHECK(fmi->reset(component), CALL_RESET);
        CHECK(fmi->setup_experiment(component, b->tolerance != NULL,
                                    b->tolerance ? *b->tolerance : 0.0, b->start_time, fmi2False,
                                    0.0),
              CALL_SETUP_EXPERIMENT);
        CHECK(fmi->enter_initialization_mode(component), CALL_ENTER_INITIALIZATION_MODE);
        if (b->n_start)
            CHECK(fmi->set_real(component, b->start_references, b->n_start,
                                b->start_values + i * b->n_start),
                  CALL_SET_START_VALUES);
        CHECK(fmi->exit_initialization_mode(component), CALL_EXIT_INITIALIZATION_MODE);
        b->steps[i] = 0;
    } else if (b->modes[i] == BATCH_STEP) {
        if (b->n_inputs)
            CHECK(fmi->set_real(component, b->input_references, b->n_inputs,
                                b->inputs + i * b->n_inputs),
                  CALL_SET_REAL);
        CHECK(fmi->do_step(component, b->start_time + (double)b->steps[i] * b->step_size, b->step_size,
                          fmi2True),
              CALL_DO_STEP);
        b->steps[i]++;
    }
    CHECK(fmi->get_real(component, b->output_references, b->n_outputs,
                        b->outputs + i * b->n_outputs),
          CALL_GET_REAL);
#undef CHECK
    return (int)worst;
}

/* Advances instances [first, end): their statuses filled in; returns the worst. */
static int advance_slice(const CsBatch *b, size_t first, size_t end) {
    int worst = fmi2OK;
    for (size_t i = first; i < end; i++) {
        b->statuses[i] = advance(b, i);
        if (b->statuses[i] > worst) worst = b->statuses[i];
    }
    return worst;
}

/* The threads beyond the caller's. A call publishes its batch and a new generation; each worker
   runs its slice of that generation and counts itself out; the caller waits for the count. */
struct CsPool {
    size_t n_threads;             /* the caller's included */
    Thread *workers;              /* n_threads - 1 */
    Lock lock;
    Condition start, done;
    const CsBatch *batch;
    unsigned long generation;
    size_t running;
    int worst, stop;
};

typedef struct {
    CsPool *pool;
    size_t index;  /* 1 .. n_threads - 1: the slice it runs */
} Worker;

static size_t slice_start(size_t n_instances, size_t n_threads, size_t index) {
    return n_instances / n_threads * index + (index < n_instances % n_threads ? index : n_instances % n_threads);
}

static void run_worker(CsPool *pool, size_t index) {
    unsigned long seen = 0;
    lock(&pool->lock);
    for (;;) {
        while (pool->generation == seen && !pool->stop) condition_wait(&pool->start, &pool->lock);
        if (pool->stop) break;
        seen = pool->generation;
        const CsBatch *batch = pool->batch;
        unlock(&pool->lock);
        const int worst = advance_slice(batch, slice_start(batch->n_instances, pool->n_threads, index),
                                        slice_start(batch->n_instances, pool->n_threads, index + 1));
        lock(&pool->lock);
        if (worst > pool->worst) pool->worst = worst;
        if (--pool->running == 0) condition_broadcast(&pool->done);
    }
    unlock(&pool->lock);
}

/* Each worker's argument lives in its own allocation, freed by the worker's start. */
#if defined(_WIN32)
static DWORD WINAPI worker_main(LPVOID argument) {
#else
static void *worker_main(void *argument) {
#endif
    Worker worker = *(Worker *)argument;
    free(argument);
    run_worker(worker.pool, worker.index);
#if defined(_WIN32)
    return 0;
#else
    return NULL;
#endif
}

static int start_worker(CsPool *pool, size_t index) {
    Worker *worker = malloc(sizeof *worker);
    if (!worker) return 0;
    worker->pool = pool;
    worker->index = index;
#if defined(_WIN32)
    pool->workers[index - 1] = CreateThread(NULL, 0, worker_main, worker, 0, NULL);
    if (pool->workers[index - 1] == NULL) { free(worker); return 0; }
#else
    if (pthread_create(&pool->workers[index - 1], NULL, worker_main, worker) != 0) {
        free(worker);
        return 0;
    }
#endif
    return 1;
}

static void join_worker(CsPool *pool, size_t index) {
#if defined(_WIN32)
    WaitForSingleObject(pool->workers[index - 1], INFINITE);
    CloseHandle(pool->workers[index - 1]);
#else
    pthread_join(pool->workers[index - 1], NULL);
#endif
}

static void stop_workers(CsPool *pool, size_t started) {
    lock(&pool->lock);
    pool->stop = 1;
    condition_broadcast(&pool->start);
    unlock(&pool->lock);
    for (size_t index = 1; index <= started; index++) join_worker(pool, index);
}

/* A pool of n_threads threads, the caller's counted (1: no thread is made); NULL when the
   system makes no more threads or memory. */
CS_LOOP_EXPORT CsPool *cs_loop_batch_pool_new(size_t n_threads) {
    if (n_threads == 0) return NULL;
    CsPool *pool = calloc(1, sizeof *pool);
    if (!pool) return NULL;
    pool->n_threads = n_threads;
    pool->workers = calloc(n_threads, sizeof *pool->workers);
    if (!pool->workers) { free(pool); return NULL; }
    lock_init(&pool->lock);
    condition_init(&pool->start);
    condition_init(&pool->done);
    for (size_t index = 1; index < n_threads; index++) {
        if (!start_worker(pool, index)) {
            stop_workers(pool, index - 1);
            pool->n_threads = 1;  /* nothing left to join in the free below */
            cs_loop_batch_pool_free(pool);
            return NULL;
        }
    }
    return pool;
}

CS_LOOP_EXPORT void cs_loop_batch_pool_free(CsPool *pool) {
    if (!pool) return;
    if (pool->n_threads > 1) stop_workers(pool, pool->n_threads - 1);
    condition_destroy(&pool->start);
    condition_destroy(&pool->done);
    lock_destroy(&pool->lock);
    free(pool->workers);
    free(pool);
}

/* Advances every instance of the batch (module comment); returns the worst status of all their
   calls, each instance's own in batch->statuses. One call at a time per pool. */
CS_LOOP_EXPORT int cs_loop_batch_advance(CsPool *pool, const CsBatch *batch) {
    const size_t n_threads = pool->n_threads < batch->n_instances ? pool->n_threads : 1;
    if (n_threads <= 1) return advance_slice(batch, 0, batch->n_instances);
    lock(&pool->lock);
    pool->batch = batch;
    pool->worst = fmi2OK;
    pool->running = pool->n_threads - 1;
    pool->generation++;
    condition_broadcast(&pool->start);
    unlock(&pool->lock);
    const int mine = advance_slice(batch, 0, slice_start(batch->n_instances, pool->n_threads, 1));
    lock(&pool->lock);
    while (pool->running > 0) condition_wait(&pool->done, &pool->lock);
    const int worst = pool->worst > mine ? pool->worst : mine;
    unlock(&pool->lock);
    return worst;
}
