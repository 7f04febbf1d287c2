#include "check.hpp"

int main() {
  auto& registry = granulate_test::Registry::get();
  int passed = 0, failed = 0;
  for (auto& [name, body] : registry.cases) {
    registry.failures_in_case = 0;
    try {
      body();
    } catch (const std::exception& error) {
      std::cerr << name << ": unexpected exception: " << error.what() << "\n";
      ++registry.failures_in_case;
    }
    if (registry.failures_in_case == 0) {
      ++passed;
    } else {
      ++failed;
      std::cerr << "FAILED: " << name << "\n";
    }
  }
  std::cout << passed << " passed, " << failed << " failed\n";
  return failed == 0 ? 0 : 1;
}
