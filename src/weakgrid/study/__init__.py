"""weakgrid.study"""
