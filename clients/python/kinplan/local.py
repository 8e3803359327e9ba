"""The old import path of :mod:`kinplan.local_server` (:class:`LocalServer`,
a kinplan server for this Python process), kept for one release; import from
:mod:`kinplan.local_server`. ``kinplan.Client.local()``, the services inside
this process without a server, is :mod:`kinplan.inprocess`."""
from .local_server import LocalServer, find_binary

__all__ = ["LocalServer", "find_binary"]
