"""weakgrid.game"""
