// How the farm commands (submit, jobs, cancel) reach a coordinator: --server, --token-file and
// --ca-file (command_line.h adds them), the token file read here.
#pragma once

#include "tessera/cli/commands.h"
#include "tessera/client/farm_api.h"

namespace tessera::cli {

/// The coordinator's client, with the client token from --token-file or $TESSERA_CLIENT_TOKEN;
/// false (the reason printed, prefixed by `who`) if the token file cannot be read or the URL is
/// not one.
bool connect(const ConnectionOptions& connection, const char* who, client::FarmApi& out);

/// A failed request in words: the answer or the URL that did not answer, and for a 401 which
/// client token was sent (from --token-file or $TESSERA_CLIENT_TOKEN, or none) and how to give one.
std::string farm_error(const client::HttpReply& reply, const ConnectionOptions& connection);

}  // namespace tessera::cli
