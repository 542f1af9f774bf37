// SPDX-License-Identifier: BSD-3-Clause
// A tiny self-contained test harness for the C++ tests (no framework to download):
//   TEST_CASE(name) { CHECK(cond); CHECK_NEAR(a, b, tol); CHECK_MAT_NEAR(A, B, tol);
//                     CHECK_THROWS(expr, ExceptionType); }
//   ARMDYN_TEST_MAIN()  // at the end of the file: runs every case, exit status 1 on any failure
// A failed check prints file:line, the expression and the values, and the case goes on; an
// exception escaping a case fails it.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace armdyn_test {

struct Case {
  const char* name;
  void (*fn)();
};

inline std::vector<Case>& registry() {
  static std::vector<Case> cases;
  return cases;
}

inline int& failures() {
  static int n = 0;
  return n;
}

struct Registrar {
  Registrar(const char* name, void (*fn)()) { registry().push_back({name, fn}); }
};

inline void fail(const char* file, int line, const std::string& what) {
  ++failures();
  std::fprintf(stderr, "%s:%d: FAILED %s\n", file, line, what.c_str());
}

inline std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

inline void check_near(double a, double b, double tol, const char* ea, const char* eb,
                       const char* file, int line) {
  const double d = std::abs(a - b);
  if (!(d <= tol))
    fail(file, line,
         std::string("CHECK_NEAR(") + ea + ", " + eb + "): " + num(a) + " vs " + num(b) +
             ", |diff| = " + num(d) + " > " + num(tol));
}

template <class A, class B>
void check_mat_near(const A& a, const B& b, double tol, const char* ea, const char* eb,
                    const char* file, int line) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) {
    fail(file, line,
         std::string("CHECK_MAT_NEAR(") + ea + ", " + eb + "): sizes " + std::to_string(a.rows()) +
             "x" + std::to_string(a.cols()) + " vs " + std::to_string(b.rows()) + "x" +
             std::to_string(b.cols()));
    return;
  }
  const Eigen::MatrixXd da = a.template cast<double>(), db = b.template cast<double>();
  const double d = (da - db).cwiseAbs().maxCoeff();
  if (!(d <= tol)) {
    std::ostringstream os;
    os.precision(12);
    os << "CHECK_MAT_NEAR(" << ea << ", " << eb << "): max |diff| = " << d << " > " << tol << "\n  "
       << ea << " =\n"
       << da << "\n  " << eb << " =\n"
       << db;
    fail(file, line, os.str());
  }
}

inline int run_all() {
  int failed_cases = 0;
  for (const Case& c : registry()) {
    const int before = failures();
    try {
      c.fn();
    } catch (const std::exception& e) {
      fail(__FILE__, __LINE__, std::string("exception in ") + c.name + ": " + e.what());
    } catch (...) {
      fail(__FILE__, __LINE__, std::string("unknown exception in ") + c.name);
    }
    const bool ok = failures() == before;
    failed_cases += ok ? 0 : 1;
    std::printf("[%s] %s\n", ok ? "  ok  " : "FAILED", c.name);
  }
  std::printf("%d of %zu cases passed\n", static_cast<int>(registry().size()) - failed_cases,
              registry().size());
  return failed_cases == 0 && !registry().empty() ? 0 : 1;
}

}  // namespace armdyn_test

#define TEST_CASE(name)                                               \
  static void name();                                                 \
  static const armdyn_test::Registrar name##_registrar(#name, &name); \
  static void name()

#define CHECK(cond)                                                         \
  do {                                                                      \
    if (!(cond)) armdyn_test::fail(__FILE__, __LINE__, "CHECK(" #cond ")"); \
  } while (0)

#define CHECK_NEAR(a, b, tol) armdyn_test::check_near((a), (b), (tol), #a, #b, __FILE__, __LINE__)

#define CHECK_MAT_NEAR(a, b, tol) \
  armdyn_test::check_mat_near((a), (b), (tol), #a, #b, __FILE__, __LINE__)

#define CHECK_THROWS(expr, Exception)                                                  \
  do {                                                                                 \
    bool thrown_ = false;                                                              \
    try {                                                                              \
      (void)(expr);                                                                    \
    } catch (const Exception&) {                                                       \
      thrown_ = true;                                                                  \
    } catch (const std::exception& e_) {                                               \
      armdyn_test::fail(                                                               \
          __FILE__, __LINE__,                                                          \
          std::string("CHECK_THROWS(" #expr ", " #Exception "): threw ") + e_.what()); \
      thrown_ = true;                                                                  \
    }                                                                                  \
    if (!thrown_)                                                                      \
      armdyn_test::fail(__FILE__, __LINE__,                                            \
                        "CHECK_THROWS(" #expr ", " #Exception "): nothing thrown");    \
  } while (0)

/// The message of the exception `expr` throws (empty, and a failure, when none).
#define THROWN_MESSAGE(expr, Exception)                                                 \
  [&]() -> std::string {                                                                \
    try {                                                                               \
      (void)(expr);                                                                     \
    } catch (const Exception& e_) {                                                     \
      return e_.what();                                                                 \
    }                                                                                   \
    armdyn_test::fail(__FILE__, __LINE__, "THROWN_MESSAGE(" #expr "): nothing thrown"); \
    return std::string();                                                               \
  }()

#define ARMDYN_TEST_MAIN() \
  int main() { return armdyn_test::run_all(); }
