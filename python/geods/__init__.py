"""geods: geometric data structures for computer graphics.

The compiled functions live in the extension module ``geods._geods``; this
package re-exports them so that ``import geods`` gives the whole API.
"""
from ._geods import *  # noqa: F401,F403
from ._geods import __version__ as __version__  # noqa: F401  (explicit: a re-export for type checkers)
