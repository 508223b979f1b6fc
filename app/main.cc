// armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints.
#include "app/cli.h"

int main(int argc, char** argv) { return armfault::CliMain(argc, argv); }
