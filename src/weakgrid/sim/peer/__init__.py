"""Peer comparison helpers (ANDES). Imports ANDES lazily; it is an optional dependency."""
