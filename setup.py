"""The one thing pyproject.toml cannot say: how to build the optional compiled loops.

``armgame/game/_ckernel.c`` (the games' loops), ``armgame/physics/_ctrig.c`` (the arm's sine for the
Python step), ``armgame/game/_cbots.c`` (the bots' forward model) and ``armgame/env/_cvector.c``
(Reach-v1's observations of a batch) must compute exactly what the Python code computes, so their build
turns off floating-point contraction (no fused multiply-add) and the compiler's own sin and cos (no
merging them into sincos; ``_ckernel.c`` calls glibc's sincos itself for the hand, after checking it
against sin and cos): see each file's opening comment. ``armgame/records/_ctimeline.c`` (a replay's
timeline read, its identity's forms) has no floating point. All are optional: without a C compiler the
install goes on, ``BatchGameSession`` and the v1 vector env's observations run numpy, the arm's sine, the
bots and the timeline's passes run in Python, with the same results.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# GCC and Clang; MSVC's default /fp:precise neither contracts nor replaces sin and cos.
EXACT_FLAGS = ["-O3", "-ffp-contract=off", "-fno-builtin-sin", "-fno-builtin-cos", "-fno-fast-math"]


class BuildExactExt(build_ext):
    def build_extensions(self) -> None:
        if self.compiler.compiler_type != "msvc":
            for extension in self.extensions:
                extension.extra_compile_args = [*extension.extra_compile_args, *EXACT_FLAGS]
        super().build_extensions()


setup(
    ext_modules=[Extension("armgame.game._ckernel", ["armgame/game/_ckernel.c", "armgame/game/_cbatch.c",
                                                     "armgame/game/_clanes.c", "armgame/game/_cevents.c",
                                                     "armgame/game/_cshoot.c"],
                           depends=["armgame/game/_ckernel.h", "armgame/game/_cstep.h", "armgame/game/_lanes.h",
                                    "armgame/physics/_trig.h"], optional=True),
                 Extension("armgame.physics._ctrig", ["armgame/physics/_ctrig.c"],
                           depends=["armgame/physics/_trig.h"], optional=True),
                 Extension("armgame.game._cbots", ["armgame/game/_cbots.c"], optional=True),
                 Extension("armgame.env._cvector", ["armgame/env/_cvector.c"], optional=True),
                 Extension("armgame.env._ccenter", ["armgame/env/_ccenter.c"],
                           depends=["armgame/game/_cstep.h", "armgame/game/_lanes.h", "armgame/physics/_trig.h",
                                    "armgame/env/_pyhypot.h", "armgame/env/_creach.h", "armgame/env/_creward.h",
                                    "armgame/env/_ccenter_lanes.h"],
                           optional=True),
                 Extension("armgame.records._ctimeline", ["armgame/records/_ctimeline.c"], optional=True)],
    cmdclass={"build_ext": BuildExactExt},
)
