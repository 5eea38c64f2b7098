// robodamp: active vibration damping for robotic milling. Each subcommand lives in
// apps/<name>_command.cpp with its options and handler; this only dispatches (apps/cli.hpp).
#include "apps/cli.hpp"

int main(int argc, char** argv) { return robodamp::apps::dispatch(argc, argv); }
