"""pam2exu's version: one place, read by the package face, the command and the exporters."""

__version__ = "0.1.0"
