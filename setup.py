"""Package discovery: ``bionav`` and its subpackages, plus the top-level ``conf/`` shipped as ``bionav.conf``.

All metadata lives in pyproject.toml; this file only exists because the
top-level ``conf/`` folder (the design card's layout) has to be installed
inside the package, which the declarative ``packages.find`` cannot express
together with automatic discovery.
"""

from setuptools import find_packages, setup

packages = [p for p in find_packages(include=["bionav", "bionav.*"])]
packages.append("bionav.conf")

setup(packages=packages, package_dir={"bionav.conf": "conf"})
