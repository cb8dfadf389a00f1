"""setuptools' build of balpipe (the project itself is declared in pyproject.toml) with one step
more: the report's Jinja templates compiled to Python modules in the built package
(:mod:`balpipe.report.template_build`), so that no process of the installed balpipe compiles
them again (0.13-0.15 s of CPU in every worker of a build). An editable install keeps compiling
them from their text."""

import importlib.util
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


def _template_build():
    """balpipe.report.template_build, loaded by its path (balpipe's dependencies are not installed here)."""
    path = Path(__file__).parent / "pipeline" / "balpipe" / "report" / "template_build.py"
    spec = importlib.util.spec_from_file_location("_balpipe_template_build", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class BuildWithTemplates(build_py):
    """build_py, then the built package's templates compiled beside them."""

    def run(self):
        super().run()
        if self.editable_mode:  # the templates stay in the source tree, compiled when used
            return
        templates = Path(self.build_lib) / "balpipe" / "templates"
        _template_build().compile_into(templates, templates / "compiled")

    def get_outputs(self, include_bytecode=True):
        templates = Path(self.build_lib) / "balpipe" / "templates" / "compiled"
        extra = sorted(str(p) for p in templates.glob("*")) if templates.is_dir() else []
        return super().get_outputs(include_bytecode) + extra


setup(cmdclass={"build_py": BuildWithTemplates})
