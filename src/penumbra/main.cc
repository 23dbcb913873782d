#include "penumbra/app/cli.h"

int main(int argc, char** argv) { return penumbra::RunCli(argc, argv); }
