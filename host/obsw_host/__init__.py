"""obsw host side (CPython only): OBC runtime, ground segment, drivers, CLI and simulators."""
