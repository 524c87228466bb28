"""weakgrid.sim"""
