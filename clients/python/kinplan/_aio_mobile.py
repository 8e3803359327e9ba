"""The old import path of :class:`kinplan.aio.AsyncMobile`, kept for one release."""
from .aio._mobile import AsyncMobile

__all__ = ["AsyncMobile"]
