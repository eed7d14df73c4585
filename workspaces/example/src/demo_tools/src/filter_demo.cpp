// Feed a few values through demo_core::Filter and print the result.
#include <iostream>
#include <vector>

#include "demo_core/filter.hpp"

int main()
{
  const std::vector<double> values{1.0, 2.0, 3.0, 4.0};
  demo_core::Filter filter(values.size());

  std::cout << "demo_tools: filtered";
  double average = 0.0;
  for (double value : values) {
    std::cout << ' ' << value;
    average = filter.update(value);
  }
  std::cout << " -> " << average << std::endl;
  return 0;
}
