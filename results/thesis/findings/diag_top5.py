# Diagnostics for FINDINGS.md (CESF): reads the PB_DEBUG_GLOBAL stderr lines of diagnostics.patch
# written to diag/{cvfh,cesf}.IMAGE.err by 'posebench recognize' (see FINDINGS.md); run in the output folder.
import json,re,sys,math
gt=json.load(open('scenes/bunny_table_07860aca/test/000001/scene_gt.json'))
for m in ['cvfh','cesf']:
  for i in range(8):
    g=[x for x in gt[str(i)] if x['obj_id']==12][0]; t=g["cam_t_m2c"]
    sig={};match=[]
    for l in open(f'diag/{m}.{i}.err'):
      p=l.split()
      if p[0]=='SIG': sig[int(p[1])]=(int(p[3]),int(p[5]),list(map(float,p[7:10])))
      if p[0]=='MATCH': match.append((float(p[3]),int(p[5]),int(p[7]),int(p[9])))
    # target cluster: cluster with sig centroid nearest t
    d={k:math.dist(v[2],t) for k,v in sig.items()}
    tc=sig[min(d,key=d.get)][0]
    on=[sig[s][0]==tc for _,s,_,_ in match]
    first=on.index(True) if True in on else -1
    r=json.load(open(f'diag/{m}.{i}.json'))
    ntsig=sum(1 for v in sig.values() if v[0]==tc)
    print(m,i,'correct' if r['errors']['correct'] else 'wrong  ', f"sigs {len(sig)} (target {ntsig}) pairs {len(match)}; top5 on target: {sum(on[:5])}; first target pair rank {first}; top5 dists", ' '.join('%.3f'%x[0] for x in match[:5]), 'first-target dist %.3f'%match[first][0])
