"""Tyre files: Magic Formula ``.tir`` files (:mod:`~.tir`, their keys :mod:`~.tir_keys`),
PAC89 JSON (:mod:`~.pac89`) and tyre measurement tables (:mod:`~.tyre_table`).
"""
