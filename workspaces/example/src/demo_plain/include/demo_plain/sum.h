#ifndef DEMO_PLAIN_SUM_H
#define DEMO_PLAIN_SUM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Return the sum of the first n values. */
long demo_plain_sum(const int *values, size_t n);

#ifdef __cplusplus
}
#endif

#endif /* DEMO_PLAIN_SUM_H */
