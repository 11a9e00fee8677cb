"""The command line shared by ab_run.py and ab_sweep.py: two pitchlab binaries A and B, the
script's own options, and after `--` arguments passed through to pitchlab."""
import os
import sys


def parse_two_binaries(parser):
    """Parses sys.argv with `parser` (which declares positional `a` and `b`) up to `--`; returns
    the namespace and the arguments after `--`. Exits 2 (parser.error) when A or B is not an
    executable file."""
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:cut])
    for binary in (args.a, args.b):
        if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
            parser.error(f"{binary}: not an executable file")
    return args, argv[cut + 1:]
