"""mercmac: write, check, simulate and upload macro programs for PI Mercury controllers."""

__version__ = "0.1.0"
