// Whether two builds produce the same bits. Workers report this at registration and the
// coordinator refuses one that differs from its own: a stitched image mixes tiles from every
// worker, so a single worker with other floating-point behaviour would make it non-deterministic.
#pragma once

#include <string>

namespace tessera {

struct BuildFingerprint {
  std::string version;  // TESSERA_VERSION
  std::string isa;      // the instruction-set baseline and compiler this build targets
  std::string probe;    // SHA-256 of the pixel sums of a small built-in render (computed once)
};

/// This build's fingerprint; the probe render (a few milliseconds) runs on the first call.
const BuildFingerprint& build_fingerprint();

/// Empty when `other` can work with this build, else the reason, for the refusal message.
std::string fingerprint_mismatch(const BuildFingerprint& mine, const BuildFingerprint& other);

}  // namespace tessera
