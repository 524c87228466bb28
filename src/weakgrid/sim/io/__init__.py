"""Importers: MATPOWER cases and ANDES systems."""
