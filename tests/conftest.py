"""The suite's environment: the compile notice off (``mbdyn.cli.compiling``), so that a
command's stderr does not depend on which test happened to compile a kernel first; the
tests of the notice turn it on for their own processes."""
import os

os.environ["MBDYN_COMPILE_NOTICE"] = "0"
