"""``python -m slewing_model.rings.superelement BEARING.toml -o FILE`` (same as ``slewing superelement``)."""
import sys

from .command import main

sys.exit(main())
