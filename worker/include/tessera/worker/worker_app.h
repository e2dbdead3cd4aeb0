// `tessera-worker` command line and signal handling; main.cpp only calls worker_main().
#pragma once

namespace tessera::farm {

int worker_main(int argc, char** argv);

}  // namespace tessera::farm
