#include "upload_slots.h"

namespace tessera::server {

namespace {

// The flags of each limit, named in a refusal so that an operator knows what to raise.
const char* total_flag(UploadKind kind) { return kind == UploadKind::Bundle ? "--max-uploads" : "--max-result-uploads"; }
const char* address_flag(UploadKind kind) {
  return kind == UploadKind::Bundle ? "--max-uploads-per-client" : "--max-result-uploads-per-host";
}
const char* noun(UploadKind kind) { return kind == UploadKind::Bundle ? "uploads (scenes, jobs)" : "result uploads"; }

}  // namespace

UploadSlots::UploadSlots(SlotLimits bundles, SlotLimits results) {
  bundles_.limits = bundles;
  results_.limits = results;
}

Status UploadSlots::acquire(const std::string& peer, const std::string& address, UploadKind kind) {
  std::lock_guard<std::mutex> lock(mu_);
  if (holders_.count(peer)) return Status::success();
  Kind& k = of(kind);
  int& mine = k.by_address[address];
  std::string detail;
  if (mine >= k.limits.per_address)
    detail = address + " is already sending " + std::to_string(mine) + " " + noun(kind) +
             ", the most one address may (tessera-server " + address_flag(kind) + " " +
             std::to_string(k.limits.per_address) + "); retry when one has ended";
  else if (k.in_use >= k.limits.total)
    detail = std::to_string(k.in_use) + " " + noun(kind) + " are being received, the most at once (tessera-server " +
             total_flag(kind) + " " + std::to_string(k.limits.total) + "); retry later";
  if (!detail.empty()) {
    if (mine == 0) k.by_address.erase(address);
    return make_error(Code::Unavailable, "uploads_busy", detail);
  }
  ++mine;
  ++k.in_use;
  holders_.emplace(peer, Holder{kind, address});
  return Status::success();
}

void UploadSlots::release(const std::string& peer) {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = holders_.find(peer);
  if (it == holders_.end()) return;
  Kind& k = of(it->second.kind);
  --k.in_use;
  auto mine = k.by_address.find(it->second.address);
  if (mine != k.by_address.end() && --mine->second <= 0) k.by_address.erase(mine);
  holders_.erase(it);
}

int UploadSlots::capacity() const { return bundles_.limits.total + results_.limits.total; }

}  // namespace tessera::server
