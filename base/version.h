// The build's version: the project's (CMakeLists.txt) and the commit it was configured from
// (git describe, "unknown" outside a checkout), e.g. "0.1.0 (2a80b92)". `daylit --version`
// prints it; report.txt and bake.json record it.
#pragma once

namespace daylit {

extern const char* const kVersion;

}  // namespace daylit
