"""A cache of derived objects per parent object, filled under one lock.

The parent (e.g. a :class:`~fastcontact.tables.Tables`) is held weakly: its entries go with
it. Each entry is built at most once, inside the lock, so concurrent callers share it.
"""
from __future__ import annotations

import threading
import weakref

__all__ = ["PerObjectCache"]


class PerObjectCache:
    """``{parent: {key: value}}`` with weakly held parents, filled under one lock."""

    def __init__(self):
        self._per = weakref.WeakKeyDictionary()
        self._lock = threading.Lock()

    def get(self, parent, key, build):
        """The value cached for (``parent``, ``key``); ``build()`` makes it on first use.

        Parameters
        ----------
        parent : object
            Weakly referenceable, hashable owner of the entry.
        key : hashable
            Which of the parent's entries.
        build : callable
            Called without arguments, under the lock, when the entry is missing.

        Returns
        -------
        object
            The cached (or newly built) value.
        """
        with self._lock:
            per = self._per.get(parent)
            if per is None:
                per = {}
                self._per[parent] = per
            if key not in per:
                per[key] = build()
            return per[key]
