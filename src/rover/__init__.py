"""rover: recursive reasoning over robot videos with vision-language models."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("rover-vlm")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0.0.0+unknown"
