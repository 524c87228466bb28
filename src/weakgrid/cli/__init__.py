"""weakgrid.cli"""
