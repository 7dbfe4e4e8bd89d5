/**
 * @file error.h
 * @brief Error codes and the check macros every softpack C function uses.
 *
 * A failing call records one human message (what and where) and returns a
 * code; callers propagate the code with SP_CALL until main prints the message
 * and exits with the code's exit status. Nothing calls exit() deep inside.
 */
#ifndef SP_ERROR_H
#define SP_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

/** Error codes (the classes of errors); sp_error_exit_status maps them to
 *  process exit statuses: 2 for SP_ERR_INPUT only, 1 for every other. */
typedef enum {
  SP_OK = 0,
  SP_ERR_SOLVER = 1,  /**< a solve failed beyond the retries allowed, or a
                           solver library failed (exit status 1) */
  SP_ERR_INPUT = 2,   /**< bad input: scene file, option, parameter (exit 2) */
  SP_ERR_IO = 3,      /**< a file could not be written (exit status 1) */
  SP_ERR_MEMORY = 4,  /**< out of memory (exit status 1) */
  SP_ERR_INTERNAL = 5, /**< a bug: an invariant did not hold (exit status 1) */
  SP_ERR_MPI = 6      /**< an MPI call failed (exit status 1) */
} sp_error_code;

/** The longest message kept (with its terminating 0). */
#define SP_ERROR_MESSAGE_MAX 2048

/** @brief Record an error message (printf format) and return @p code. */
int sp_error_set(int code, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/** @brief The message recorded by the last sp_error_set (empty if none). */
const char *sp_error_message(void);
/** @brief Forget the recorded message. */
void sp_error_clear(void);
/** @brief The process exit status for an error code (0, 1 or 2). */
int sp_error_exit_status(int code);
/** @brief The class of an error code in words ("bad input", "memory",
 *         "solver", "output", "MPI", "internal"; "ok" for SP_OK). */
const char *sp_error_class_name(int code);
/** @brief Mark the recorded error as agreed by every rank of a run
 *         (agree.h); @p adopted: 1 if it is another rank's error. Any later
 *         sp_error_set or sp_error_clear unmarks it. */
void sp_error_mark_agreed(int adopted);
/** @brief 1 if the recorded error was agreed by every rank (agree.h). */
int sp_error_agreed(void);
/** @brief 1 if the recorded error is another rank's, learnt by agreement. */
int sp_error_adopted(void);

/** Return @p code with a message unless @p cond holds. */
#define SP_CHECK(cond, code, ...)                                              \
  do {                                                                         \
    if (!(cond)) return sp_error_set((code), __VA_ARGS__);                     \
  } while (0)

/** Propagate a non-zero code returned by @p expr. */
#define SP_CALL(expr)                                                          \
  do {                                                                         \
    int sp_call_rc_ = (expr);                                                  \
    if (sp_call_rc_ != SP_OK) return sp_call_rc_;                              \
  } while (0)

/** Allocate @p n zeroed elements into @p ptr or return SP_ERR_MEMORY. */
#define SP_ALLOC(ptr, n)                                                       \
  do {                                                                         \
    size_t sp_alloc_n_ = (size_t)(n);                                          \
    (ptr) = calloc(sp_alloc_n_ ? sp_alloc_n_ : 1, sizeof(*(ptr)));             \
    if (!(ptr))                                                                \
      return sp_error_set(SP_ERR_MEMORY, "out of memory allocating %zu x %zu " \
                          "bytes for %s", sp_alloc_n_, sizeof(*(ptr)), #ptr);  \
  } while (0)

#ifdef __cplusplus
}
#endif
#endif
