# Diagnostics for FINDINGS.md (CESF): target-cluster ranks from diag_all/ (PB_TOPK_PER_CLUSTER=1, top_k 1000, no refinement).
import json,math,sys
gt=json.load(open('scenes/bunny_table_07860aca/test/000001/scene_gt.json'))
def q(R):  # rotation matrix (row-major 9) -> quaternion
  m=[[R[0],R[1],R[2]],[R[3],R[4],R[5]],[R[6],R[7],R[8]]]
  tr=m[0][0]+m[1][1]+m[2][2]
  w=math.sqrt(max(0,1+tr))/2; x=math.sqrt(max(0,1+m[0][0]-m[1][1]-m[2][2]))/2
  y=math.sqrt(max(0,1-m[0][0]+m[1][1]-m[2][2]))/2; z=math.sqrt(max(0,1-m[0][0]-m[1][1]+m[2][2]))/2
  x=math.copysign(x,m[2][1]-m[1][2]); y=math.copysign(y,m[0][2]-m[2][0]); z=math.copysign(z,m[1][0]-m[0][1])
  return (w,x,y,z)
for m in sys.argv[1:]:
  for i in range(8):
    g=[x for x in gt[str(i)] if x['obj_id']==12][0]; t=g['cam_t_m2c']; qg=q(g['cam_R_m2c'])
    sig={}; hyps=[]; order=[]
    for l in open(f'diag_all/{m}.{i}.err'):
      p=l.split()
      if p[0]=='SIG': sig[int(p[1])]=(int(p[3]),list(map(float,p[7:10])))
      if p[0]=='HYP':
        d=float(p[2]); s=int(p[4]); mo=int(p[6]); th=list(map(float,p[10:13])); R=list(map(float,p[14:23]))
        te=math.dist(th,t); re=1-abs(sum(a*b for a,b in zip(q(R),qg)))
        key=(d,s,mo)
        if key not in order: order.append(key)
        hyps.append((order.index(key),s,mo,te,re))
    dd={k:math.dist(v[1],t) for k,v in sig.items()}
    tc=sig[min(dd,key=dd.get)][0]
    # matches of the target cluster in distance order
    tm=[]
    for k in order:
      if sig[k[1]][0]==tc: tm.append(k)
    def ok(h): return h[3]<50 and h[4]<0.05
    def rotok(h): return h[4]<0.05
    first=None; firstrot=None
    for j,k in enumerate(tm):
      hs=[h for h in hyps if order[h[0]]==k]
      if first is None and any(ok(h) for h in hs): first=j
      if firstrot is None and any(rotok(h) for h in hs): firstrot=j
    # best achievable: any hyp on target at all with te<50?
    tes=[h[3] for h in hyps if sig[h[1]][0]==tc]
    print(m,i,f"target cluster {tc}: {sum(1 for v in sig.values() if v[0]==tc)} sigs, {len(tm)} pairs; first pair giving a correct initial pose at target-rank {first}; first with rotation ok {firstrot}; min init t-err on target {min(tes):.0f} mm")
