#include "demo_core/filter.hpp"

#include <stdexcept>

namespace demo_core
{

Filter::Filter(std::size_t window)
: window_(window)
{
  if (window_ == 0) {
    throw std::invalid_argument("demo_core::Filter: window must be at least 1");
  }
}

double Filter::update(double value)
{
  values_.push_back(value);
  sum_ += value;
  if (values_.size() > window_) {
    sum_ -= values_.front();
    values_.pop_front();
  }
  return sum_ / static_cast<double>(values_.size());
}

demo_interfaces::msg::Reading Filter::update(const demo_interfaces::msg::Reading & reading)
{
  demo_interfaces::msg::Reading filtered = reading;
  filtered.value = update(reading.value);
  return filtered;
}

}  // namespace demo_core
