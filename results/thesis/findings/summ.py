import json,sys,collections
agg=collections.OrderedDict()
for f in sys.argv[1:]:
  for l in open(f):
    r=json.loads(l)
    k=(r['scene'],r['descriptor'],r['refinement'],json.dumps(r.get('params',{}),sort_keys=True),r.get('added_noise_mm',0))
    c=agg.setdefault(k,collections.Counter())
    c['n']+=1; c['correct']+=bool(r.get('correct'))
    cr=r.get('correct_rank')
    c['exists']+= (cr is not None and cr>=0)
    c['hyp']+=r.get('hypotheses',0) or 0
for k,c in sorted(agg.items()):
  print(*k, f"correct {c['correct']}/{c['n']}  correct-hyp-exists {c['exists']}/{c['n']}  mean hyps {c['hyp']/c['n']:.1f}")
