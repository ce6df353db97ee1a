// Subcommands of the resmr tool, one file each.
#pragma once

/// resmr synth NX NY NZ -o FILE [options]; argv[1] is "synth".
int SynthCommand(int argc, char** argv);

/// resmr simplify MODEL [options]; argv[1] is "simplify".
int SimplifyCommand(int argc, char** argv);
