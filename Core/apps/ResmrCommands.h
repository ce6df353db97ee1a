// Subcommands of the resmr tool, one file each.
#pragma once

#include "CornerPointModel.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

/// `text` as a JSON string literal, quotes included.
inline std::string JsonString(const std::string& text)
{
  std::string out = "\"";
  for (char c : text)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (static_cast<unsigned char>(c) < 32)
    {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
      out += escaped;
    }
    else
    {
      out += c;
    }
  }
  return out + "\"";
}

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

/// resmr build INPUT -o OUT.resmr [options]; argv[1] is "build".
int BuildCommand(int argc, char** argv);

/// resmr info [--regions] FILE.resmr: levels, regions, sizes and errors as JSON; with
/// --regions every region's record too (level, index, counts, errors, bounds, chunk CRCs).
int MultiresolutionInfo(const char* path, bool listRegions = false);

/// resmr add-properties FILE.resmr RESULTS... [-o FILE.resmrp]; argv[1] is "add-properties".
int AddPropertiesCommand(int argc, char** argv);
