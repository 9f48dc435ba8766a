"""The bottom layer, imported by every other and importing none of them: counter-based random
numbers, the compile cache and kernels, errors, zenoh sessions, the generic wire, the memory
codec, scenario tables, the registries' entries, plots."""
