#ifndef DEMO_CORE__FILTER_HPP_
#define DEMO_CORE__FILTER_HPP_

#include <cstddef>
#include <deque>

#include "demo_interfaces/msg/reading.hpp"

namespace demo_core
{

/// Moving average over the last `window` values.
class Filter
{
public:
  explicit Filter(std::size_t window);

  /// Add a value and return the average of the last `window` values.
  double update(double value);

  /// Filter a reading's value; header and unit are kept.
  demo_interfaces::msg::Reading update(const demo_interfaces::msg::Reading & reading);

private:
  std::size_t window_;
  std::deque<double> values_;
  double sum_ = 0.0;
};

}  // namespace demo_core

#endif  // DEMO_CORE__FILTER_HPP_
