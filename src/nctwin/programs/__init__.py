"""Generators of the part programs the chapters need; each returns G-code text or a Toolpath."""
