"""The generated kernel (backend "llvm"): the numpy reference's plans flattened into a program
(:mod:`.program`, :mod:`.terms`, :mod:`.output_maps`), the LLVM IR written from it (:mod:`.kernel`,
per sample :mod:`.links`, :mod:`.blocks`, :mod:`.world`, :mod:`.signs`, :mod:`.dense_solve`, :mod:`.trig`,
:mod:`.outputs`, arithmetic :mod:`.build`), compiled, cached on disk and run on threads
(:mod:`.driver`, :mod:`.cache`, :mod:`.jobs`)."""
