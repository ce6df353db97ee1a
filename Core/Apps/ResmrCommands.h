// Subcommands of the resmr tool, one file each.
#pragma once

#include <stdexcept>
#include <string>

/// The value after option argv[a] (advancing a); throws std::invalid_argument if missing.
inline const char* OptionValue(int& a, int argc, char** argv)
{
  if (a + 1 >= argc)
  {
    throw std::invalid_argument(std::string(argv[a]) + " needs a value");
  }
  return argv[++a];
}

/// resmr synth NX NY NZ -o FILE [options]; argv[1] is "synth".
int SynthCommand(int argc, char** argv);

/// resmr simplify MODEL [options]; argv[1] is "simplify".
int SimplifyCommand(int argc, char** argv);
