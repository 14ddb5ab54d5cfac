"""The one thing pyproject.toml cannot say: how to build the optional compiled batch kernel.

``armgame/game/_ckernel.c`` must compute exactly what the Python single session computes, so
its build turns off floating-point contraction (no fused multiply-add) and the compiler's own
sin and cos (no merging them into sincos): see the file's opening comment. The extension is
optional: without a C compiler the install goes on and ``BatchGameSession`` runs numpy.
"""

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# GCC and Clang; MSVC's default /fp:precise neither contracts nor replaces sin and cos.
EXACT_FLAGS = ["-O2", "-ffp-contract=off", "-fno-builtin-sin", "-fno-builtin-cos", "-fno-fast-math"]


class BuildExactExt(build_ext):
    def build_extensions(self) -> None:
        if self.compiler.compiler_type != "msvc":
            for extension in self.extensions:
                extension.extra_compile_args = [*extension.extra_compile_args, *EXACT_FLAGS]
        super().build_extensions()


setup(
    ext_modules=[Extension("armgame.game._ckernel", ["armgame/game/_ckernel.c"], optional=True)],
    cmdclass={"build_ext": BuildExactExt},
)
