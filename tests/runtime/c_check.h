/* CHECK(cond) for the C tests: on failure, print the condition and where, and return 1 from main. */
#ifndef KDM_TESTS_C_CHECK_H
#define KDM_TESTS_C_CHECK_H

#include <stdio.h>

#define CHECK(cond)                                                            \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      return 1;                                                                \
    }                                                                          \
  } while (0)

#endif
