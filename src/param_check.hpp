#pragma once
// The one way parameter structs validate a field: a one-line ParamError that names the
// field, the value and the allowed range ("PlaneParams.max_angle_deg = 95: must be ...").
#include <sstream>
#include <string>

#include "wul3d/error.hpp"

namespace wul3d::detail {

/// Throws unless `ok`. `owner` prefixes the field name ("PlaneParams"); empty for the paper's
/// own symbols, whose names are the CLI's flags (k, alpha, delta, gamma, psi).
template <class T>
void require_param(bool ok, const std::string& owner, const char* name, const T& value,
                   const char* range) {
    if (ok) return;
    std::ostringstream msg;
    msg << (owner.empty() ? "" : owner + ".") << name << " = " << value << ": must be " << range;
    throw ParamError(msg.str());
}

}  // namespace wul3d::detail
