"""``python -m slewing_model.superelement BEARING.toml -o FILE`` (same as ``slewing superelement``)."""
import sys

from .command import main

sys.exit(main())
