// Fixture of scripts/check_function_size_test.py: every function's body length (closing brace's
// line minus opening brace's) is written beside it, counted by hand and confirmed by clang-tidy's
// readability-function-size (LineThreshold 0). Not compiled.
#include <string>  // a directive with a brace in it is not code: {

namespace outer {
namespace {

int Short() { return 1; }  // 0 lines

// A brace in a comment { does not open anything.
std::string Tricky() {  // 5 lines
  const char* brace = "{ not a block";
  const char c = '{';
  const std::string raw = R"x({ still a string })x";
  return std::string(brace) + c + raw;
}

}  // namespace

struct Point {
  int x{0};  // a member initializer, not a function
  int y = 0;
  Point() : x{1}, y(2) {}  // 0 lines: the brace after x is its initializer
  explicit Point(int v)
      : x(v),
        y{v} {  // 2 lines
    x += 1;
  }
  int operator()(int a) const {  // 2 lines
    return a + x;
  }

 public:
  bool operator<(const Point& o) const { return x < o.x; }  // 0 lines
};

enum class Colour : int { kRed, kGreen };

template <typename T>
T Twice(const T& t) {  // 6 lines: a lambda counts towards its function
  auto add = [](const T& a, const T& b) {
    return a + b;
  };
  const int table[] = {1, 2, 3};
  return add(t, t) + T(table[0] - 1);
}

const int kTable[] = {1, 2, 3};  // an initializer at namespace scope

}  // namespace outer

extern "C" {
int CFunction(int a) {  // 2 lines
  return a;
}
}

int Point_Long(int a) {  // 12 lines
  int sum = 0;
  for (int i = 0; i < a; ++i) {
    sum += i;
  }
  if (sum > 10) {
    sum -= 10;
  } else {
    sum += 10;
  }
  // closing braces in a string: "}}}"
  return sum;
}
