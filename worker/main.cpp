// tessera-worker: leases tile passes from a coordinator and renders them.
#include "tessera/worker/worker_app.h"

int main(int argc, char** argv) { return tessera::farm::worker_main(argc, argv); }
