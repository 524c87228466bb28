def from_psse(*a, **k): raise NotImplementedError
