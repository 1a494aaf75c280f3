#include "command.hpp"

int main(int argc, char** argv) { return geods::cli::run_cli(argc, argv); }
