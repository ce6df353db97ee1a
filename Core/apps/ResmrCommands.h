// Subcommands of the resmr tool, one file each.
#pragma once

#include "CornerPointModel.h"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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

/// `text` as a whole number; throws std::invalid_argument naming `what` if it is not one.
inline int64_t ParseInteger(const char* text, const char* what)
{
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text, &end, 10);
  if (errno == ERANGE)
  {
    throw std::invalid_argument(std::string(what) + " is too large (got '" + text + "')");
  }
  if (errno != 0 || end == text || *end != '\0')
  {
    throw std::invalid_argument(std::string(what) + " must be a whole number (got '" + text + "')");
  }
  return value;
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
