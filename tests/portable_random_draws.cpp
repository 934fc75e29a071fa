// Prints draws of runtime/portable_random.hpp's distributions, exactly (hex floats), one per
// line: the same text from any standard library is what portable_random_libcxx.sh checks.
// With --std, the standard library's own distributions instead (shown, not checked: they
// differ between libraries, which is why portable_random.hpp exists).
#include <cstdio>
#include <cstring>
#include <random>

#include "runtime/portable_random.hpp"

namespace {

template <class Engine, class Uniform, class Gaussian>
void print_draws(Engine& engine, Uniform& uniform, Gaussian& gaussian, int count) {
  for (int i = 0; i < count; ++i) {
    const double value = i % 3 == 0 ? uniform(engine) : gaussian(engine);  // one draw per line
    std::printf("%a\n", value);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool standard = argc > 1 && std::strcmp(argv[1], "--std") == 0;
  const int count = standard ? 8 : 3000;
  for (unsigned seed : {1u, 3u, 5489u}) {
    std::mt19937 engine32(seed);
    std::mt19937_64 engine64(seed);
    const auto on_both_engines = [&](auto& uniform, auto& gaussian) {
      print_draws(engine32, uniform, gaussian, count);
      print_draws(engine64, uniform, gaussian, count);
    };
    if (standard) {
      std::uniform_real_distribution<double> uniform(-0.3, 2.5);
      std::normal_distribution<double> gaussian(0.7, 1.9);
      on_both_engines(uniform, gaussian);
    } else {
      const quadgen::runtime::UniformReal uniform(-0.3, 2.5);
      quadgen::runtime::Normal gaussian(0.7, 1.9);
      on_both_engines(uniform, gaussian);
    }
  }
  return 0;
}
