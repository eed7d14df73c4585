#include <stdio.h>

#include "demo_plain/sum.h"

int main(void)
{
  const int values[] = {1, 2, 3, 4};
  const size_t n = sizeof(values) / sizeof(values[0]);

  printf("demo_plain: sum");
  for (size_t i = 0; i < n; ++i) {
    printf(" %d", values[i]);
  }
  printf(" -> %ld\n", demo_plain_sum(values, n));
  return 0;
}
