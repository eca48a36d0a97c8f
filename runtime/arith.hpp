// arith — the language's integer arithmetic, decided once.
//
// Autumn numbers are C++ ints in the reference: + - * wrap modulo 2^32 in
// practice (signed overflow, reproduced here as unsigned wrapping), / truncates
// toward zero, % takes the sign of the dividend, and division or modulo by zero
// or INT_MIN / -1 kill the reference process. We report those as errors with
// one text. The interpreter, the lowering's compile-time folding and emitted
// code all call these functions, so there is one rule and one message.
#pragma once
#include <climits>
#include <cstdint>
#include <string>
#include <string_view>

namespace autumn::arith {

inline int32_t add(int32_t a, int32_t b) { return static_cast<int32_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b)); }
inline int32_t sub(int32_t a, int32_t b) { return static_cast<int32_t>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b)); }
inline int32_t mul(int32_t a, int32_t b) { return static_cast<int32_t>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b)); }
inline int32_t neg(int32_t a) { return static_cast<int32_t>(0u - static_cast<uint32_t>(a)); }

// Empty when a / b and a % b are defined; otherwise the error text for the
// operator spelled `op` (as written in the source: "/", "%").
inline std::string division_error(int32_t a, int32_t b, std::string_view op) {
  if (b == 0) return "division by zero in '" + std::string(op) + "' (the reference interpreter crashes here)";
  if (a == INT_MIN && b == -1)
    return "integer overflow in '" + std::string(op) + "' (the reference interpreter crashes here)";
  return {};
}
// Only when division_error(a, b, ...) is empty.
inline int32_t div_unchecked(int32_t a, int32_t b) { return a / b; }
inline int32_t mod_unchecked(int32_t a, int32_t b) { return a % b; }

}  // namespace autumn::arith
