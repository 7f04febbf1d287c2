// A minimal test harness: TEST_CASE registers a function, CHECK records failures.
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

namespace granulate_test {

struct Registry {
  std::vector<std::pair<std::string, std::function<void()>>> cases;
  int failures_in_case = 0;
  static Registry& get() {
    static Registry registry;
    return registry;
  }
};

struct Register {
  Register(const char* name, std::function<void()> body) {
    Registry::get().cases.emplace_back(name, std::move(body));
  }
};

inline void fail(const char* file, int line, const std::string& what) {
  ++Registry::get().failures_in_case;
  std::cerr << file << ":" << line << ": check failed: " << what << "\n";
}

inline std::string show(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

inline bool close(double a, double b, double rtol, double atol = 0) {
  return std::abs(a - b) <= atol + rtol * std::max(std::abs(a), std::abs(b));
}

}  // namespace granulate_test

#define GT_CAT2(a, b) a##b
#define GT_CAT(a, b) GT_CAT2(a, b)
#define TEST_CASE(name)                                                                                 \
  static void GT_CAT(test_body_, __LINE__)();                                                           \
  static granulate_test::Register GT_CAT(test_register_, __LINE__)(name, GT_CAT(test_body_, __LINE__)); \
  static void GT_CAT(test_body_, __LINE__)()

#define CHECK(condition)                                                    \
  do {                                                                      \
    if (!(condition)) granulate_test::fail(__FILE__, __LINE__, #condition); \
  } while (0)

#define CHECK_CLOSE(a, b, rtol)                                                                      \
  do {                                                                                               \
    const double check_a_ = (a), check_b_ = (b);                                                     \
    if (!granulate_test::close(check_a_, check_b_, (rtol)))                                          \
      granulate_test::fail(__FILE__, __LINE__,                                                       \
                           std::string(#a " ~ " #b ": ") + granulate_test::show(check_a_) + " vs " + \
                               granulate_test::show(check_b_));                                      \
  } while (0)

/// |a - b| <= atol + rtol max(|a|, |b|): for values that may be zero.
#define CHECK_NEAR(a, b, rtol, atol)                                                                 \
  do {                                                                                               \
    const double check_a_ = (a), check_b_ = (b);                                                     \
    if (!granulate_test::close(check_a_, check_b_, (rtol), (atol)))                                  \
      granulate_test::fail(__FILE__, __LINE__,                                                       \
                           std::string(#a " ~ " #b ": ") + granulate_test::show(check_a_) + " vs " + \
                               granulate_test::show(check_b_));                                      \
  } while (0)

#define CHECK_THROWS(expression, type)                                                           \
  do {                                                                                           \
    bool thrown_ = false;                                                                        \
    try {                                                                                        \
      (void)(expression);                                                                        \
    } catch (const type&) {                                                                      \
      thrown_ = true;                                                                            \
    }                                                                                            \
    if (!thrown_) granulate_test::fail(__FILE__, __LINE__, #expression " did not throw " #type); \
  } while (0)
