"""Fixtures of the command-line tests."""

import pytest
from helpers import write_tiny_folder


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A 3 x 3 Vardy-named database of smooth random panoramas (:func:`helpers.write_tiny_folder`)."""
    return write_tiny_folder(tmp_path_factory.mktemp("db") / "tiny")
