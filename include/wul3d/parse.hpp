#pragma once
/// @file parse.hpp
/// The text of the options that take numbers ("U,V", "fx,fy,cx,cy"), parsed one way for the
/// command (`--select`, `--intrinsics`, `view --orbit`) and the Python module
/// (`wul3d.run(select=..., intrinsics=...)`), so that both accept and refuse the same values
/// with the same messages.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "wul3d/camera.hpp"

namespace wul3d {

/// Splits "a,b,c" into exactly `expected` numbers (each whole item a number: "3abc" is
/// refused); throws ParamError naming `flag` and the text.
std::vector<double> parse_numbers(const std::string& flag, const std::string& text,
                                  std::size_t expected);

/// The pixel (u, v) of `--select` from two numbers: each must lie in [0, kMaxSidePx) before
/// it becomes an int (1e20, NaN and inf have no int value); fractions are cut toward zero.
/// ParamError names `--select` and `text`, how the caller spelled it.
std::pair<int, int> select_pixel(double u, double v, const std::string& text);

/// `--select U,V`: parse_numbers, then select_pixel.
std::pair<int, int> parse_select(const std::string& text);

/// `--intrinsics fx,fy,cx,cy`: an override for frames of any size (width = height = 0),
/// checked by PinholeIntrinsics::validate_unsized; ParamError names the flag.
PinholeIntrinsics parse_intrinsics_override(const std::string& text);

}  // namespace wul3d
