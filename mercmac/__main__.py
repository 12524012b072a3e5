"""`python -m mercmac`."""
from mercmac.cli import main

main()
