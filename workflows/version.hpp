#pragma once
namespace stentsim {
inline constexpr const char* kVersion = "0.1.0";
}
